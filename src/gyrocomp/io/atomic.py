"""Atomic output: write to a temporary file beside the target, then rename over it."""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
import stat
import tempfile
from collections.abc import Iterable, Iterator
from glob import escape as glob_escape
from pathlib import Path

from ..errors import InputError


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path in the target's folder; on success it replaces ``path`` in one rename.

    On any exception the temporary file is removed and ``path`` is left as it was. A symbolic link is refused
    (:func:`refuse_link`), never written through: in a folder others can write to (``/tmp``), a link planted where
    the output will go would otherwise have the output replace whatever file it points at, whoever owns it. A
    FIFO, a device, a socket or a folder is refused, since a rename would replace it with a regular file. The
    temporary file is created with ``O_EXCL`` in the output's own folder (:func:`tempfile.mkstemp`), and the
    rename replaces the directory entry ``path`` itself: a link planted between the check and the rename is
    replaced, not followed.
    """
    target = check_output_file(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{target}: folder {folder} does not exist; create it first")
    tmp_path = _staged(target, folder, tempfile.mkstemp)
    try:
        yield tmp_path
        os.chmod(tmp_path, _mode_for(target))
        os.replace(tmp_path, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def arrow_source(path: str | os.PathLike):
    """``path`` as the table libraries (pyarrow, pandas) take it: the path, or, for a file name that is not valid
    UTF-8 (any bytes are legal on Linux, and Python keeps them as surrogate escapes), the file opened for reading
    in binary, which those libraries read as well."""
    text = os.fspath(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return open(text, "rb")
    return text


#: a temporary output's name: this prefix, the writing process's id, a tag of the target's name, random letters
TEMP_PREFIX = ".gyrocomp-"


@contextlib.contextmanager
def atomic_folder(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a new temporary folder beside ``path`` (named as :func:`atomic_path`'s temporary files, so that the
    next writer of the same output removes one a killed process left); it is removed when the block ends, and
    whatever the block moved out of it into place stays."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    staged = _staged(target, folder, tempfile.mkdtemp)
    try:
        yield staged
    finally:
        shutil.rmtree(staged, ignore_errors=True)


def _staged(target: Path, folder: Path, make) -> Path:
    """A new temporary file (``make`` :func:`tempfile.mkstemp`) or folder (:func:`tempfile.mkdtemp`) for
    ``target`` in ``folder``, after removing those a killed writer of the same target left."""
    tag = _tag(target.name)
    _remove_stale(folder, tag)
    try:
        made = make(prefix=f"{TEMP_PREFIX}{os.getpid()}-{tag}.", suffix=".tmp", dir=folder)
    except OSError as exc:  # name the output the user gave, not the temporary file
        raise InputError(f"{target}: cannot write there ({exc.strerror or exc})") from None
    if isinstance(made, tuple):
        os.close(made[0])
        made = made[1]
    return Path(made)


def _tag(name: str) -> str:
    """A short ASCII tag of a file name for its temporary files (any name the OS allows, long or not UTF-8)."""
    return "".join(c if c.isascii() and (c.isalnum() or c in "._-") else "_" for c in name)[:40]


def _remove_stale(folder: Path, tag: str) -> None:
    """Remove the temporary outputs for the same target that a killed process (SIGKILL, a power cut) left: those
    whose process is gone. A process still running keeps its own."""
    for stale in folder.glob(f"{TEMP_PREFIX}*-{glob_escape(tag)}.*.tmp"):
        pid = stale.name[len(TEMP_PREFIX) :].split("-", 1)[0]
        if pid.isdigit() and not process_alive(int(pid)):
            if stale.is_dir() and not stale.is_symlink():
                shutil.rmtree(stale, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    stale.unlink()


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine (another user's counts as alive)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process: alive
        return True
    return True


#: the names of the standard streams, refused as outputs with their own words (each is a link besides)
_STANDARD_STREAMS = ("/dev/stdout", "/dev/stderr", "/dev/stdin", "/dev/fd/1", "/dev/fd/2", "/dev/tty")


def check_output_file(path: str | os.PathLike) -> Path:
    """The regular file (existing or new) that writing to ``path`` means; refuse anything else."""
    text = os.fspath(path)
    if text == "-" or text in _STANDARD_STREAMS or text.startswith("/proc/self/fd/"):
        raise InputError(f"{text}: gyrocomp writes its outputs to files, not to the standard streams; name a file")
    if text.endswith(("/", os.sep)):
        raise InputError(f"{text}: names a folder (it ends in {text[-1]}); name the output file itself")
    target = Path(path)
    refuse_link(target)
    try:
        mode = target.stat().st_mode
    except FileNotFoundError:
        return target
    if not stat.S_ISREG(mode):
        kind = (
            "a folder"
            if stat.S_ISDIR(mode)
            else "a FIFO"
            if stat.S_ISFIFO(mode)
            else "a device"
            if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else "a socket"
            if stat.S_ISSOCK(mode)
            else "not a regular file"
        )
        raise InputError(f"{path}: is {kind}; outputs are written to regular files (name a new path)")
    return target


def refuse_link(path: str | os.PathLike, what: str = "outputs are") -> None:
    """Raise :class:`InputError` if ``path`` is a symbolic link: gyrocomp never writes through one (``what``
    names the kind of file in the message)."""
    target = Path(path)
    if target.is_symlink():
        try:
            points_to = f" (to {os.readlink(target)})"
        except OSError:
            points_to = ""
        raise InputError(
            f"{path}: is a symbolic link{points_to}; {what} never written through a link, which could "
            "replace a file elsewhere: name the file itself, or remove the link"
        )


def _mode_for(target: Path) -> int:
    """The permissions of the new file: the read and write bits of the file it replaces where this process's user
    owns that file, else 0o666 less the umask (mkstemp's temporary files are private, 0o600). A file another user
    planted (in a shared folder) lends nothing, and no new file is setuid, setgid, sticky or executable."""
    try:
        old = target.stat()
    except FileNotFoundError:
        old = None
    if old is not None and old.st_uid == os.geteuid():
        return old.st_mode & 0o666
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def require_unchanged(path: str | os.PathLike, before: os.stat_result) -> None:
    """Refuse in one line an input that changed while it was read (another program still writing it, cutting it
    short or replacing it): its size, modification time or file differ from ``before``, its state when the
    reading began. What was read from it is then not the file, so nothing is written from it."""
    try:
        after = os.stat(path)
    except OSError:
        raise InputError(f"{path}: removed or replaced while it was read; nothing written from it") from None
    if (after.st_size, after.st_mtime_ns, after.st_ino) != (before.st_size, before.st_mtime_ns, before.st_ino):
        change = (
            f"{before.st_size} bytes when the reading began, {after.st_size} at its end"
            if after.st_size != before.st_size
            else "modified or replaced during the reading"
        )
        raise InputError(
            f"{path}: changed while it was read ({change}: still being written, or cut short); "
            "nothing written from it: read it again once it is complete"
        )


@contextlib.contextmanager
def folder_lock(path: str | os.PathLike) -> Iterator[None]:
    """Hold an exclusive lock (``flock``) on the folder of ``path`` for the block: writers of that folder that take
    it (learners saving states) check what is there and write in turn, never between another's check and write.
    The lock goes with the process; it is advisory (a program that does not take it is not stopped)."""
    folder = Path(path).parent
    try:
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    except OSError as exc:
        raise InputError(f"{path}: cannot open its folder to lock it ({exc.strerror or exc})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def write_texts_atomic(folder: str | os.PathLike, texts: dict[str, str]) -> list[Path]:
    """Write several files into ``folder`` all or none: every one goes to a temporary file first, and only when
    all are written are they renamed into place (a full disk while writing leaves the old files as they were).
    Returns the paths written."""
    folder = Path(folder)
    with contextlib.ExitStack() as stack:
        temps = []
        for name, text in texts.items():
            tmp = stack.enter_context(atomic_path(folder / name))  # each renames on exit, after all are written
            tmp.write_text(text, encoding="utf-8")
            temps.append(folder / name)
    return temps


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def refuse_to_overwrite_inputs(
    output: str | os.PathLike, inputs: Iterable[str | os.PathLike], option: str = "-o", what: str = "an input file"
) -> None:
    """Raise :class:`InputError` if ``output`` is the same file as any of ``inputs`` (by name, through links, or a
    hard link to it), or a symbolic link (:func:`refuse_link`): the checks a command makes on its output (a file or
    a folder) before it does the work; ``what`` says in the message what ``inputs`` are. An output file is checked
    besides by :func:`check_output_file` (the command line's type of output files)."""
    refuse_link(output)
    out = Path(output)
    for item in inputs:
        src = Path(item)
        same = os.path.realpath(out) == os.path.realpath(src)  # realpath, unlike resolve, survives link loops
        if not same and out.exists() and src.exists():
            same = os.path.samefile(out, src)
        if same:
            raise InputError(f"{option} {output}: this is {what}; choose another output path")
