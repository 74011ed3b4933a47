"""The layer contract, checked on the import graph of the source (no import-linter needed): a module imports
only from its own layer or the layers below it, the graph has no cycle, and no function imports a project module
(optional third-party extras may still be imported where they are used)."""

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "gyrocomp"

#: bottom to top; a module belongs to the first layer one of whose prefixes it matches. Every layer above the
#: foundation is one or more folders of its own; the package root holds only the foundation's modules.
LAYERS = (
    # pure functions and helpers any layer may use: errors, physical units, the effects' equations, spilling
    (
        "foundation",
        (
            "_version",
            "errors",
            "units",
            "threads",
            "jsontext",
            "rounding",
            "c_literals",
            "effects",
            "spilled_series",
            "option_spelling",
            "lazy",
        ),
    ),
    # what a recording is and what is measured of it: the recording and its preparation, motion (stillness,
    # static positions), measures (figures of merit, noise terms, plausibility), Allan statistics, simulation
    ("signals", ("recording", "motion", "runs", "measures", "allan", "simulation")),
    ("io", ("io",)),
    # the frozen curves a calibration holds (polynomial, network, lookup table, hysteresis) and their registry
    ("curves", ("curves",)),
    # the frozen, versioned calibration, its triads and fit report, and its application (compensate)
    ("calibration", ("calibration",)),
    # the estimators: each effect's fit, the held-out folds and the model choice, the online learner
    ("fitting", ("fitting",)),
    # the pipelines that combine the estimators into a calibration, and the one fit entry point
    ("pipelines", ("models",)),
    ("evaluation", ("evaluation",)),
    # files read in chunks: apply, convert, evaluate and the noise analysis of files of any length
    ("files", ("files",)),
    # fleets fit, measure and judge many units: above evaluation, below the reports that draw them
    ("fleet", ("fleet",)),
    ("output", ("report", "export")),
    ("cli", ("cli", "__main__")),
    ("package", ("",)),
)


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _layer(module: str) -> int:
    for rank, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            if module == prefix or module.startswith(prefix + ".") or (prefix == "" and module == ""):
                return rank
    raise AssertionError(f"{module or 'gyrocomp'}: in no layer of the contract; add it to LAYERS")


def _imports(path: Path) -> tuple[set[str], list[tuple[int, str]]]:
    """(project modules imported, [(line, module)] of those imported inside a function)."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    tree = ast.parse(path.read_text())
    found, inner = set(), []
    functions = [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
    nested = {id(n) for f in functions for n in ast.walk(f) if n is not f}
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package.split(".") if package else []
            base = base[: len(base) - node.level + 1]
            stem = ".".join(base + ([node.module] if node.module else []))
            if node.module:
                targets = [stem]
            else:  # from . import x: x may be a module
                targets = [".".join(filter(None, (stem, a.name))) for a in node.names]
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [node.module] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            targets = [
                n[len("gyrocomp.") :] if n != "gyrocomp" else ""
                for n in names
                if n == "gyrocomp" or n.startswith("gyrocomp.")
            ]
        for target in targets:
            while target and not (
                (SRC / target.replace(".", "/")).with_suffix(".py").exists()
                or (SRC / target.replace(".", "/") / "__init__.py").exists()
            ):
                target = target.rpartition(".")[0]  # a name imported from a module, not a module
            found.add(target)
            if id(node) in nested:
                inner.append((node.lineno, target))
    return found, inner


GRAPH = {_module_name(p): _imports(p) for p in sorted(SRC.rglob("*.py"))}


def test_every_module_is_in_a_layer():
    for module in GRAPH:
        _layer(module)


@pytest.mark.parametrize("module", sorted(GRAPH))
def test_imports_go_down_the_layers(module):
    rank = _layer(module)
    upward = sorted(t for t in GRAPH[module][0] if _layer(t) > rank)
    assert not upward, f"{module} ({LAYERS[rank][0]}) imports from a higher layer: " + ", ".join(
        f"{t} ({LAYERS[_layer(t)][0]})" for t in upward
    )


def test_no_function_imports_a_project_module():
    inner = [f"{m}:{line} imports {t or 'gyrocomp'}" for m, (_, found) in GRAPH.items() for line, t in found]
    assert not inner, "; ".join(inner)


def test_the_import_graph_has_no_cycle():
    # the package root re-exports and is imported by no module below it, so it is left out
    graph = {m: {t for t in deps if t != m and t in GRAPH and t != ""} for m, (deps, _) in GRAPH.items() if m}
    state: dict[str, int] = {}

    def visit(node, path):
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycle = path[path.index(nxt) :] + [nxt]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])


def test_the_parser_sees_relative_absolute_and_inner_imports(tmp_path):
    # the checks above are not vacuous: known edges of the graph are found
    assert {"calibration.calibration", "effects", "recording"} <= GRAPH["calibration.compensate"][0]
    assert "models.options" in GRAPH["cli.fit"][0] and "io.atomic" in GRAPH["calibration.calibration"][0]
    assert _layer("measures.merit") < _layer("models.pipelines") and _layer("fitting.selection") == _layer(
        "fitting.thermal"
    )
    with pytest.raises(AssertionError, match="newthing: in no layer"):
        _layer("newthing")


def test_no_two_modules_share_a_file_name():
    """A file name says one thing: outside ``__init__.py`` and the commands (``cli/``, whose modules may carry the
    name of what they call), no two modules have the same name."""
    seen: dict[str, list[str]] = {}
    for path in SRC.rglob("*.py"):
        module = _module_name(path)
        if path.name in ("__init__.py", "__main__.py") or module.startswith("cli."):
            continue
        seen.setdefault(path.name, []).append(module)
    assert {name: mods for name, mods in seen.items() if len(mods) > 1} == {}


def _folder(module: str) -> str:
    return module.split(".")[0] if "." in module else ""


def test_no_two_folders_import_each_other():
    """The folders' graph has no two-way edge (the layers allow imports within one layer, not both ways)."""
    edges = {
        (_folder(m), _folder(t))
        for m, (deps, _) in GRAPH.items()
        for t in deps
        if _folder(m) and _folder(t) and _folder(m) != _folder(t)
    }
    assert sorted((a, b) for a, b in edges if (b, a) in edges and a < b) == []


def test_the_folder_check_sees_a_two_way_edge():
    assert _folder("motion.stillness") == "motion" and _folder("errors") == ""
    assert ("runs", "motion") in {(_folder(m), _folder(t)) for m, (deps, _) in GRAPH.items() for t in deps}


def test_the_init_files_only_export():
    """A package's ``__init__.py`` names what it exports (imports, ``__all__``, the lazy table of names imported
    when first used); the code lives in modules whose names say what they hold."""
    allowed_targets = {"__all__", "_EXPORTS", "__getattr__", "__dir__"}
    code = []
    for path in SRC.rglob("__init__.py"):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
                continue  # the docstring
            if isinstance(node, ast.Assign) and all(
                isinstance(t, ast.Name)
                and t.id in allowed_targets
                or isinstance(t, ast.Tuple)
                and all(isinstance(e, ast.Name) and e.id in allowed_targets for e in t.elts)
                for t in node.targets
            ):
                continue
            code.append(f"{path.relative_to(SRC)}:{node.lineno}")
    assert code == []


def _private_imports(text: str, module: str) -> list[str]:
    """``module:line name`` for each ``_private`` name that ``text`` imports from a project module."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").split(".")[0] == "gyrocomp"):
            out += [
                f"{module}:{node.lineno} {a.name}"
                for a in node.names
                if a.name.startswith("_") and not a.name.startswith("__")
            ]
    return out


def test_no_private_name_is_imported_from_another_module():
    """A name another module needs is public in the module where it belongs (the seam is drawn there)."""
    hits = [h for path in sorted(SRC.rglob("*.py")) for h in _private_imports(path.read_text(), _module_name(path))]
    assert hits == []


def test_the_private_import_check_sees_one():
    text = "from .refit import _hidden, visible\nfrom gyrocomp.io import _also\nfrom numpy import _x\n"
    assert _private_imports(text, "io.planted") == ["io.planted:1 _hidden", "io.planted:2 _also"]
