"""The README and the documentation site: the README stays a first visitor's page (under 10 KB, every link to a
page that exists), every page of docs/ is in the site's navigation, and the README's Python example runs."""

import importlib
import inspect
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_the_readme_is_short_and_links_to_pages_that_exist():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.encode()) < 10_000
    head = text.splitlines()[:6]
    assert any(line.startswith("make demo") for line in head) and any(line.startswith("make test") for line in head)
    links = re.findall(r"\]\(([^)]+)\)", text)
    assert len(links) >= 10
    for link in links:
        assert (ROOT / link).is_file(), link


def test_the_sites_home_page_is_the_readme():
    """docs/index.md is the README with its docs/ links made relative to the site (tools/site_index.py writes it):
    the landing page carries the set-up and the measured figures, and cannot drift from the README."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("site_index", ROOT / "tools" / "site_index.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert (ROOT / "docs" / "index.md").read_text(encoding="utf-8") == module.site_index(readme), (
        "docs/index.md differs from the README: run python tools/site_index.py"
    )
    assert "## Measured" in readme and "](docs/" not in module.site_index(readme)


def test_every_page_is_in_the_sites_navigation():
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8").split("\nnav:", 1)[1]
    listed = set(re.findall(r":\s*([\w-]+\.md)\s*$", nav, flags=re.M))
    pages = {p.name for p in (ROOT / "docs").glob("*.md")}
    assert pages == listed


def test_the_readmes_python_example_runs(tmp_path, monkeypatch):
    """The README's Python example, as written, in a folder where ``gyrocomp init`` ran on logs of another
    project's layout (tab-separated, other column names, named .csv): read through the project file, the rates
    are the file's, and the model compensates the flight file (before: ``gyrocomp.read`` ignored the project file,
    and the snippet failed on any file with other column names)."""
    from gyrocomp.simulation import get_profile, simulate

    from .conftest import run

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", text, flags=re.S).group(1)
    prof = get_profile("cycle", set_points_degc=(-10.0, 50.0), cycles=1)
    sims = {}
    for k, name in enumerate(("chamber_1.csv", "chamber_2.csv", "flight.csv")):
        sims[name] = rec = simulate("consumer", profile=prof, rate_hz=2.0, seed=k).recording
        rows = ["Stamp\tGyrX\tGyrY\tGyrZ\tTemp"] + [
            "\t".join([f"{t:.2f}", *(f"{v:.9g}" for v in g), f"{temp:.2f}"])
            for t, g, temp in zip(rec.time_s, rec.gyro_dps, rec.temperature_degc)
        ]
        (tmp_path / name).write_text("\n".join(rows) + "\n")
    made = run("init", "chamber_1.csv", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exec(code, scope)  # noqa: S102 - the README's own example
    flight = scope["gyrocomp"].read("flight.csv", config="gyrocomp.toml")
    np.testing.assert_allclose(flight.gyro_dps, sims["flight.csv"].gyro_dps, rtol=1e-8)
    assert scope["model"].axes and scope["compensated"].n_samples == flight.n_samples
    assert np.ptp(scope["compensated"].gyro_dps[:, 0]) < 0.5 * np.ptp(flight.gyro_dps[:, 0])


@pytest.mark.parametrize("page", sorted(p.name for p in (ROOT / "docs").glob("*.md")))
def test_each_page_opens_with_its_one_title(page):
    text = re.sub(r"```.*?```", "", (ROOT / "docs" / page).read_text(encoding="utf-8"), flags=re.S)
    text = re.sub(r"\A---\n.*?\n---\n\n", "", text, flags=re.S)  # the page's metadata (its search boost) first
    titles = [line for line in text.splitlines() if line.startswith("# ")]
    assert len(titles) == 1 and text.startswith(titles[0])


def _api_objects():
    """What the API page shows: each ``::: name`` and, of a class or module, its public members defined there."""
    for dotted in re.findall(r"^::: (\S+)$", (ROOT / "docs" / "api.md").read_text(), re.M):
        parts = dotted.split(".")
        for i in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:i]))
                break
            except ImportError:
                continue
        for part in parts[i:]:
            obj = getattr(obj, part)
        yield dotted, obj
        if inspect.ismodule(obj):
            members = [
                (n, m)
                for n, m in vars(obj).items()
                if not n.startswith("_")
                and (inspect.isfunction(m) or inspect.isclass(m))
                and m.__module__ == obj.__name__
            ]
        elif inspect.isclass(obj):
            members = [
                (n, m)
                for n, m in vars(obj).items()
                if not n.startswith("_") and (inspect.isfunction(m) or isinstance(m, (classmethod, staticmethod)))
            ]
        else:
            members = []
        for name, _member in members:
            yield f"{dotted}.{name}", getattr(obj, name)


#: name endings that carry a unit: their entry says it in brackets
UNIT_ENDINGS = ("_degc", "_dps", "_s", "_hz", "_g", "_deg_per_h")


def test_every_object_on_the_api_page_documents_each_parameter_with_its_unit():
    """numpydoc sections (Parameters, or Attributes for a record) on everything the API page shows that takes a
    parameter; each parameter named there, and one whose name carries a unit given it in brackets."""
    shown = list(_api_objects())
    assert len(shown) >= 40
    missing = []
    for dotted, obj in shown:
        if inspect.ismodule(obj) or not callable(obj):
            continue
        try:
            params = [p for p in inspect.signature(obj).parameters.values() if p.name not in ("self", "cls")]
        except (TypeError, ValueError):
            continue
        doc = inspect.getdoc(obj) or ""
        section = re.search(r"^(?:Parameters|Attributes)\n-{3,}\n(.*?)(?=^\w[\w ]*\n-{3,}|\Z)", doc, re.M | re.S)
        if params and section is None:
            missing.append(f"{dotted}: no Parameters section")
            continue
        for p in params:
            names = r"(?:\*{0,2}\w+, )*\*{0,2}" + re.escape(p.name) + r"(?:, \*{0,2}\w+)*"  # "a, b : type"
            entry = re.search(rf"^{names}(?: :[^\n]*)?\n((?:[ \t]+[^\n]*\n?)*)", section.group(1), re.M)
            if entry is None:
                missing.append(f"{dotted}: {p.name} not described")
            elif p.name.endswith(UNIT_ENDINGS) and "[" not in entry.group(0):
                missing.append(f"{dotted}: {p.name} without its unit in brackets")
    assert not missing, "\n".join(missing)
