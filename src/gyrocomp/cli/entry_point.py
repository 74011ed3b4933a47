"""The ``gyrocomp`` command line: the group, its commands loaded when used, and the mapping of errors to exit codes.

Exit status: 0 success, 2 bad input or usage, 1 other failures. Errors are one line on stderr;
``--debug`` adds the traceback.

This module needs only click: ``gyrocomp --help`` and ``gyrocomp --version`` start without numpy, scipy or
pandas. Each command lives in its own module (``gyrocomp.cli.fit``, ...), imported when the command is looked up,
so a command loads only what it uses; ``common`` holds what they share (reading files, options) and ``render``
the tables they print. The one-line descriptions are listed here (a test checks they match the commands' own).
"""

from __future__ import annotations

import errno
import functools
import importlib
import os
import re
import resource
import shlex
import signal
import sys
import traceback
import warnings

import click

from .._version import __version__
from ..errors import CHECKS, GyrocompError, InputError, LayoutError, PlausibilityWarning, printable, silence_pattern
from .projectfile import PROJECT_KEY, defaults_for, load_project, unknown_defaults

EXIT_INPUT = 2
EXIT_FAILURE = 1

#: every command: its name, its module in gyrocomp.cli (the command is the function of the same name there), and
#: its one-line help (``gyrocomp --help`` shows it shortened to the terminal)
COMMANDS = {
    "simulate": (
        "simulate",
        "Simulate calibration runs of a sensor preset through a test profile, with the exact truth.",
    ),
    "fit": (
        "fit",
        "Fit a compensation model on calibration RUNS (each one power-on, the gyro at rest), or on the still "
        "moments of field logs.",
    ),
    "learn": (
        "learn",
        "Learn a temperature model from the still moments of LOGS, as the online learner would on the "
        "vehicle: each log one power-on, replayed in the order given.",
    ),
    "apply": (
        "apply",
        "Compensate IN with MODEL: same columns and rows out, gyro columns compensated (a ROS bag into a "
        "bag: every message copied, the IMU topic compensated).",
    ),
    "show": (
        "show",
        "What MODEL is: its axes (curve, range, lag, memory, G), the runs it came from (with their device "
        "ids), and the drift its held-out folds expect.",
    ),
    "split": (
        "split",
        "Cut LOG into runs, one file each, so that a recording of several "
        "power-ons, poses or temperature legs becomes the runs a fit takes.",
    ),
    "convert": (
        "convert",
        "Write IN (any format gyrocomp reads) as the canonical CSV or Parquet table OUT, or a bag as another bag.",
    ),
    "check": (
        "check",
        "Check RUNS before a fit, as fit and fleet fit do: one verdict line per run (ok, warning with "
        "its expected cost, or refused with the reason).",
    ),
    "validate": (
        "validate",
        "Held-out drift on RUNS of raw, PX4's cubic, ArduPilot's cubic, a plain cubic, gyrocomp's "
        "default and the best model a firmware carries.",
    ),
    "evaluate": (
        "evaluate",
        "Bias offset, bias instability and integration time of RUNS, raw and compensated with MODEL.",
    ),
    "allan": (
        "allan",
        "Allan deviation with 68 % intervals and IEEE 952 noise terms (N, B, K, Q, R) of each axis of FILE.",
    ),
    "noise": (
        "noise",
        "Noise model of static LOGS for an estimator: white noise and random walk (and Gauss-Markov "
        "terms) whose Allan deviation is at or above the upper end of every log's 95 % interval at "
        "every averaging time, beside the IEEE 952 fit.",
    ),
    "export": (
        "export",
        "Write MODEL as autopilot parameters (temperature cubic, accelerometer offsets and scales) or as C code.",
    ),
    "report": (
        "report",
        "One self-contained HTML report of MODEL judged on RUNS: the model, the figures of merit, bias "
        "against temperature, raw and compensated series, Allan deviations, g-sensitivity; with "
        "--validate-on, the held-out drift of each method on those calibration runs.",
    ),
    "plot": ("plot", "Single figures as PNG, SVG or PDF (from the suffix of -o)."),
    "plan": (
        "plan",
        "How much chamber time is enough, and which run to record next: the drift MODEL should leave on a use "
        "profile, and candidate runs scored per hour of chamber time.",
    ),
    "fleet": (
        "fleet",
        "Production calibration of many units: fit them on Dask into a calibration store, judge them "
        "against limits, look a unit's calibration up and export it.",
    ),
    "init": (
        "project",
        "Write a project file for LOG's kind of table: its columns and units guessed from their "
        "names and magnitudes, said one by one, read by every command run in this folder (a file of named "
        "arrays, HDF5, MAT or .npz: the same from its arrays).",
    ),
    "config": ("project", "The project file in use (gyrocomp.toml in this folder, or --config)."),
    "demo": (
        "demo",
        "The main job on built-in simulated data: fit on chamber runs, compensate a held-out run, score "
        "it, and write the HTML report.",
    ),
}


def short_help(text: str, limit: int) -> str:
    """The first sentence of ``text``, cut at a word with ``...`` when longer than ``limit`` characters (what
    click shows for a command's help in its parent's list)."""
    sentence = text.split(". ", 1)[0].rstrip(".")
    if len(sentence) <= limit:
        return sentence
    cut = sentence[: max(limit - 3, 1)].rsplit(" ", 1)[0]
    return cut.rstrip(",;:") + "..."


class LazyGroup(click.Group):
    """A click group whose commands are imported when one is looked up (running it or its --help), and whose
    own help lists them from :data:`COMMANDS` without importing anything."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        """The command, imported now, with the project file's options as its defaults (``gyrocomp.toml``)."""
        if name not in COMMANDS:
            return None
        command = getattr(importlib.import_module(f"gyrocomp.cli.{COMMANDS[name][0]}"), name)
        _LOOKED_UP.append(command)
        _name_the_project_first(command)
        if name == "init":  # init writes the project file: one that does not load must not stop it
            return command
        if PROJECT_KEY not in ctx.meta:
            ctx.meta[PROJECT_KEY] = None if _no_config(ctx) else load_project(ctx.params.get("config"), tuple(COMMANDS))
        project = ctx.meta[PROJECT_KEY]
        if project is not None:
            ctx.default_map = {**(ctx.default_map or {}), name: defaults_for(project, command, name)}
            if unknown_defaults(project, [command]):  # another command's, or none's: every command asked
                _refuse_unknown_defaults(project)
        return command

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        limit = formatter.width - 6 - max(len(name) for name in COMMANDS)
        with formatter.section("Commands"):
            formatter.write_dl([(name, short_help(text, limit)) for name, (_, text) in sorted(COMMANDS.items())])


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gyrocomp")
@click.option("--debug", is_flag=True, help="Show tracebacks on errors.")
@click.option("--quiet", "-q", is_flag=True, help="Print only errors (no tables, no warnings).")
@click.option(
    "--allow",
    "allowed",
    multiple=True,
    type=click.Choice(CHECKS),
    metavar="CHECK",
    help=f"Silence one plausibility check (repeatable): {', '.join(CHECKS)}.",
)
@click.option(
    "--config",
    "config",
    default=None,
    metavar="FILE",
    help="Project file of default options (default: gyrocomp.toml in this folder, when there is one).",
)
@click.option(
    "--no-config",
    "no_config",
    is_flag=True,
    help="Read no project file, not even gyrocomp.toml in this folder (as GYROCOMP_NO_CONFIG=1 does).",
)
@click.pass_context
def cli(ctx, debug, quiet, allowed, config, no_config):
    """Remove the deterministic errors of MEMS gyros (temperature drift, thermal lag, hysteresis,
    g-sensitivity) from logs, and measure what is left.

    Typical flow: fit on calibration runs, apply to new data, evaluate or report, export to firmware
    or an autopilot; allan for noise; demo for all of it on simulated data.

    Units: angular rate deg/s, acceleration g, temperature degC, time s.
    """
    ctx.obj = {"debug": debug, "quiet": quiet}
    if quiet:  # only errors: warnings too are silent (their checks still run; --json keeps every figure)
        ctx.with_resource(warnings.catch_warnings())
        warnings.simplefilter("ignore")
    if allowed:
        ctx.with_resource(warnings.catch_warnings())
        for check in allowed:
            warnings.filterwarnings("ignore", message=silence_pattern(check), category=PlausibilityWarning)


# -- entry point ------------------------------------------------------------------------------------
#: the commands this process has looked up (the one it runs): their options say which flag sets which parameter
_LOOKED_UP: list[click.Command] = []
#: the option objects whose fields messages name (``FitOptions.hysteresis: ...``): the field is the flag's
_OPTION_OBJECT = re.compile(r"\b(?:FitOptions|Polynomial|Network)\.(?=\w)")
_MAPPING = re.compile(r"--columns \{'(\w+)': '([^']*)'\}")  # the API's mapping, as --columns writes it


#: the environment variable that, set to anything but empty or 0, reads no project file (as --no-config)
NO_CONFIG_VARIABLE = "GYROCOMP_NO_CONFIG"


def _no_config(ctx: click.Context) -> bool:
    """Whether this run reads no project file: --no-config, or GYROCOMP_NO_CONFIG set (a --config FILE wins over
    the variable, not over the flag)."""
    if ctx.params.get("no_config"):
        if ctx.params.get("config") is not None:
            raise click.UsageError("--config and --no-config: give one of them")
        return True
    return ctx.params.get("config") is None and os.environ.get(NO_CONFIG_VARIABLE, "") not in ("", "0")


def _refuse_unknown_defaults(project) -> None:
    """Refuse a project file whose [defaults] holds a key that no command has (every command imported to tell)."""
    everyone = [getattr(importlib.import_module(f"gyrocomp.cli.{m}"), n) for n, (m, _) in COMMANDS.items()]
    unknown = unknown_defaults(project, everyone)
    if unknown:
        raise InputError(
            f"{project.path}: [defaults] {', '.join(unknown)}: no command has such an option (misspelt? each key "
            "is a command's long option without its dashes, e.g. gyro-unit, window)"
        )


def _name_the_project_first(command: click.Command) -> None:
    """Make ``command`` (and a group's commands) say, before it runs, which of its options the project file set:
    a ``gyrocomp.toml`` left in a folder changes what every command there reads and fits, and nothing else would
    say so. Wrapped once; ``--help`` and a refused option stop before it."""
    for each in (command, *getattr(command, "commands", {}).values()):
        if each.callback is not None and not getattr(each.callback, _SAYS_PROJECT, False):
            each.callback = _said_first(each.callback)


def _said_first(callback):
    @functools.wraps(callback)
    def said_first(*args, **kwargs):
        _name_the_project(click.get_current_context())
        return callback(*args, **kwargs)

    setattr(said_first, _SAYS_PROJECT, True)
    return said_first


#: the mark of a command callback that names the project file first
_SAYS_PROJECT = "_gyrocomp_says_project"


def _name_the_project(ctx: click.Context) -> None:
    """One note on stderr naming the project file and the options of this command it set (not with ``--quiet``)."""
    root = ctx.find_root()
    project = root.meta.get(PROJECT_KEY)
    if project is None or (root.obj or {}).get("quiet"):
        return
    used = [
        next((o for o in param.opts if o.startswith("--")), param.opts[0])
        for param in ctx.command.params
        if isinstance(param, click.Option)
        and param.name
        and ctx.get_parameter_source(param.name) is click.core.ParameterSource.DEFAULT_MAP
    ]
    if used:
        click.echo(
            f"gyrocomp: note: {printable(project.path)} sets {', '.join(used)} (an option on the command "
            "line wins; gyrocomp config show prints the file)",
            err=True,
        )


def _options(command: click.Command) -> list[click.Option]:
    """The options of a command, and of a group's commands."""
    found = [p for p in command.params if isinstance(p, click.Option)]
    for sub in getattr(command, "commands", {}).values():
        found += _options(sub)
    return found


def in_cli_words(message: str, commands: list[click.Command] | None = None) -> str:
    """``message`` with the Python parameters it names (``name:`` or ``name=value``) as the flags that set them
    (``--flag:``, ``--flag value``; a switch, ``name=True``, as the flag alone).

    The library names a parameter as the option's own name: every option of a command is declared under the name
    of the library parameter it sets (``--drop-nan`` sets ``drop_nonfinite``; the reading options are made from
    the fields of :class:`gyrocomp.io.ReadOptions`), so the flags come from the options of ``commands`` (default:
    the command this process runs), with no table to keep in step."""
    options = _options(cli) + [o for c in (_LOOKED_UP if commands is None else commands) for o in _options(c)]
    flags = {o.name: max(o.opts, key=len) for o in options if o.name}
    switches = {o.name for o in options if o.is_flag}
    # the group's own options (--debug, --quiet, switches both) are always there: neither pattern is empty
    message = _OPTION_OBJECT.sub("", message)
    message = re.sub(r"(?<![\w.\-/])(" + "|".join(map(re.escape, switches)) + r")=True\b", r"\1=", message)
    names = "|".join(map(re.escape, sorted(flags, key=len, reverse=True)))

    def flag(m: re.Match) -> str:
        name, sep, after = m.group(1), m.group(2), m.string[m.end() : m.end() + 1]
        if sep == ":":
            return flags[name] + ":"
        return flags[name] + (" " if after and not after.isspace() and after not in ",;)" else "")

    message = re.sub(r"(?<![\w.\-/])(" + names + r")([:=])", flag, message)
    return _MAPPING.sub(lambda m: f"--columns {m.group(1)}={m.group(2)}", message)


def _init_hint(exc: InputError) -> str:
    """For a file whose time or gyro is not where gyrocomp looks (outside ``init``): that ``init`` guesses them."""
    if not isinstance(exc, LayoutError) or any(c.name == "init" for c in _LOOKED_UP):
        return ""
    return f"; or let `gyrocomp init {shlex.quote(str(exc.path))}` guess them from the names into a project file"


def _show_warning(message, category, filename, lineno, file=None, line=None):
    click.echo(f"gyrocomp: warning: {printable(in_cli_words(str(message)))}", err=True)


#: what a library says when the machine runs out of memory, threads or file descriptors (pyarrow's thread pool,
#: Python's threads), each an error of the environment, not of gyrocomp
_EXHAUSTED = re.compile(
    r"failed to launch worker thread|can't start new thread|cannot allocate memory|"
    r"out of memory|resource temporarily unavailable|too many open files|failed to map segment",
    re.IGNORECASE,
)
_OUT_OF_MEMORY = (
    "not enough memory (or threads) for this size of data under this machine's limits; read less at "
    "once (--columns for the channels needed, --time A:B for a stretch, apply streams tables) or "
    "run it where more memory is allowed (ulimit -v)"
)


def _resource_exhausted(exc: BaseException) -> bool:
    """Whether ``exc`` says the machine ran out of memory, threads or file descriptors."""
    return (
        isinstance(exc, MemoryError)
        or bool(_EXHAUSTED.search(str(exc)))
        and (type(exc).__name__.startswith("Arrow") or isinstance(exc, (RuntimeError, OSError, ImportError)))
    )


def _environment_message(exc: BaseException) -> str:
    """One line for an error of the machine rather than of gyrocomp: the file and what to do."""
    if isinstance(exc, OSError) and exc.errno in (errno.EMFILE, errno.ENFILE):
        return "too many files open at once for this machine's limit (ulimit -n); raise it, or give fewer files at once"
    if _resource_exhausted(exc):
        return _OUT_OF_MEMORY
    where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
    hint = {
        errno.EACCES: "check its permissions",
        errno.EPERM: "check its permissions",
        errno.ENOSPC: "the disk is full; free space and run again",
        errno.EFBIG: "the file is too large here",
        errno.ELOOP: "a symbolic link loops",
        errno.EROFS: "the file system is read-only",
    }
    reason = exc.strerror or str(exc) or type(exc).__name__
    return f"{where}{reason.lower()}" + (f"; {hint[exc.errno]}" if getattr(exc, "errno", None) in hint else "")


class _Terminated(SystemExit):
    """The command was stopped by a signal (SIGTERM, SIGHUP)."""

    def __init__(self, signum: int):
        super().__init__(128 + signum)
        self.signum = signum


#: what the command says when it is stopped: the atomic writers removed their temporary files on the way out
_NOTHING_HALF_WRITTEN = "outputs not finished were removed, nothing half-written is left"


def _exit_on_termination() -> None:
    """SIGTERM, SIGHUP and SIGINT (Ctrl-C) end the command as an exception would: every temporary output is
    removed on the way out (the atomic writers clean up on any exception) and nothing half-written is left at a
    target."""

    def stop(signum, frame):
        for sig in caught:  # a second Ctrl-C must not break the cleanup on the way out
            signal.signal(sig, signal.SIG_IGN)
        raise _Terminated(signum)

    caught = []

    for name in ("SIGTERM", "SIGHUP", "SIGINT"):
        # Ctrl-C too: click would turn it into its own abort, after an empty line; one ignored (nohup, a
        # background job) stays ignored
        if hasattr(signal, name) and signal.getsignal(getattr(signal, name)) is not signal.SIG_IGN:
            signal.signal(getattr(signal, name), stop)
            caught.append(getattr(signal, name))


#: the address space the numeric libraries need to load and read a small file [bytes] (under 0.6 GB, OpenBLAS
#: loops for ever retrying its buffers; 1 GB leaves room for the data)
MIN_ADDRESS_SPACE_BYTES = 1 << 30


#: the environment variables that size the numeric libraries' thread pools when they load
THREAD_POOL_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def one_thread_per_pool() -> None:
    """Keep the numeric libraries' thread pools to one thread each, before they load; settings already in the
    environment are kept. A command's algebra is many small solves, whose BLAS threads (one per core) wait for
    each other on a machine another job shares; under an address-space limit OpenBLAS reserves tens of MB per
    thread, and a pool that cannot start its threads fails to load or waits for ever."""
    for name in THREAD_POOL_VARIABLES:
        os.environ.setdefault(name, "1")


def _within_address_limit() -> None:
    """Under an address-space limit (``ulimit -v``): refuse one too small to load the numeric libraries, and use
    the system's allocator for pyarrow, whose failures it reports instead of aborting (settings already in the
    environment kept)."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        return
    if soft < MIN_ADDRESS_SPACE_BYTES:  # OpenBLAS would retry its buffers for ever while loading
        raise InputError(
            f"this process may map {soft / 1e6:.0f} MB (ulimit -v); gyrocomp needs at least "
            f"{MIN_ADDRESS_SPACE_BYTES / 1e9:.0f} GB to load its numeric libraries: raise the limit"
        )
    os.environ.setdefault("ARROW_DEFAULT_MEMORY_POOL", "system")


def _unexpected(exc: Exception) -> int:
    """Say an exception no layer turned into a message, in one line, and return the status: the machine's limits
    (pyarrow's or Python's threads or memory) as an error of the environment, anything else as a bug."""
    if _resource_exhausted(exc):
        click.echo(f"gyrocomp: error: {_environment_message(exc)}", err=True)
        return EXIT_INPUT
    click.echo(
        f"gyrocomp: internal error: {type(exc).__name__}: {printable(str(exc))} (run with --debug for the traceback)",
        err=True,
    )
    return EXIT_FAILURE


def _before_the_command(exc: click.ClickException) -> str:
    """For an option of gyrocomp itself given after the command (``fit --config F``): where it goes."""
    if not isinstance(exc, click.NoSuchOption):
        return ""
    own = {o for p in cli.params for o in (*p.opts, *getattr(p, "secondary_opts", ()))}
    if exc.option_name not in own:
        return ""
    return f"; {exc.option_name} is an option of gyrocomp itself: give it before the command (gyrocomp {exc.option_name} ... COMMAND)"


def main(argv: list[str] | None = None) -> int:
    """Console entry point: runs the command and returns (and, as a script, exits with) its status."""
    if argv is None:
        _exit_on_termination()
    args = sys.argv[1:] if argv is None else list(argv)
    debug = "--debug" in args
    if sys.stdout is None or sys.stdout.closed:  # run with stdout closed (>&-): what it would print goes nowhere
        sys.stdout = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 - for the rest of the process
    previous = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        if argv is None:
            one_thread_per_pool()
            _within_address_limit()
        result = cli.main(args=args, prog_name="gyrocomp", standalone_mode=False)
        status = result if isinstance(result, int) else 0
    except click.exceptions.Exit as exc:
        status = exc.exit_code
    except click.exceptions.Abort:
        click.echo(f"gyrocomp: interrupted; {_NOTHING_HALF_WRITTEN}", err=True)
        status = EXIT_FAILURE
    except _Terminated as exc:
        what = (
            "interrupted (Ctrl-C)" if exc.signum == signal.SIGINT else f"stopped by {signal.Signals(exc.signum).name}"
        )
        click.echo(f"gyrocomp: {what}; {_NOTHING_HALF_WRITTEN}", err=True)
        status = exc.code
    except click.ClickException as exc:  # usage errors: bad option, missing argument
        if debug:
            traceback.print_exc()
        # click lists choices on indented lines ("Choose from:\n\ta,\n\tb"): one line here
        message = re.sub(r"\s*\n\s*", " ", exc.format_message())
        hint = _before_the_command(exc)
        message = message.rstrip(".") + hint if hint else message
        click.echo(f"gyrocomp: error: {printable(message)}", err=True)
        status = EXIT_INPUT if isinstance(exc, click.UsageError) else exc.exit_code
    except InputError as exc:
        if debug:
            traceback.print_exc()
        click.echo(f"gyrocomp: error: {printable(in_cli_words(str(exc)) + _init_hint(exc))}", err=True)
        status = EXIT_INPUT
    except GyrocompError as exc:
        if debug:
            traceback.print_exc()
        click.echo(f"gyrocomp: error: {printable(str(exc))}", err=True)
        status = EXIT_FAILURE
    except (OSError, MemoryError) as exc:  # the environment, not a bug: permissions, a full disk, a link loop
        if debug:
            traceback.print_exc()
        click.echo(f"gyrocomp: error: {printable(_environment_message(exc))}", err=True)
        status = EXIT_INPUT
    except Exception as exc:  # noqa: BLE001 - the last line of defence: one line, status 1
        if debug:
            traceback.print_exc()
        status = _unexpected(exc)
    finally:
        warnings.showwarning = previous
    if argv is None:
        sys.exit(status)
    return status


__all__ = ["COMMANDS", "LazyGroup", "cli", "in_cli_words", "main"]
