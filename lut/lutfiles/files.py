"""Writing files atomically: to a temporary file in the same folder, renamed
onto the target when complete (``os.replace``) and removed when the write
fails, so an interrupted write never leaves a partial file and never loses
the old one.  The writers of lut, the add-on and the scripts go through
``atomic_target`` (or ``atomic_write_bytes`` / ``atomic_write_text``),
except where Blender writes the file itself (a .blend library, a render).

The temporary file is hidden and named ``.<stem>.<pid>@<host>.<random>.partial<suffix>``:
a later write in the folder removes it if its writer was killed
(``remove_stale_partials``), and ``lut.lutfiles.cleanup`` lists it."""

from __future__ import annotations

import contextlib
import errno
import os
import pathlib
import re
import socket
import stat
import tempfile
import time

#: A partial file from a writer that cannot be asked whether it still runs
#: (another host, or no process ids) is stale after this many seconds.
STALE_PARTIAL_SECONDS = 24 * 3600

_PARTIAL = re.compile(r"^\..*?\.(?:(?P<pid>\d+)@(?P<host>[A-Za-z0-9_-]*)\.)?[A-Za-z0-9_]+\.partial(?:\.[^.]*)?$")


def _host() -> str:
    return re.sub(r"[^A-Za-z0-9_-]", "_", socket.gethostname())[:64]


def _process_alive(pid: int) -> bool:
    if os.name != "posix":  # os.kill would terminate the process on Windows
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def is_stale_partial(path, now=None) -> bool:
    """Whether ``path`` is the temporary file of an atomic write whose writer
    is gone: a process of this host that no longer runs (killed, crashed),
    or, for another host's, older than STALE_PARTIAL_SECONDS."""
    path = pathlib.Path(path)
    match = _PARTIAL.match(path.name)
    if match is None:
        return False
    try:
        age = (time.time() if now is None else now) - path.stat().st_mtime
    except OSError:
        return False
    if match["pid"] and match["host"] == _host():
        return not _process_alive(int(match["pid"]))
    return age > STALE_PARTIAL_SECONDS


def remove_stale_partials(directory) -> list[pathlib.Path]:
    """Remove the temporary files that interrupted atomic writes left in
    ``directory`` (``is_stale_partial``); returns them."""
    removed = []
    try:
        candidates = sorted(pathlib.Path(directory).glob(".*.partial*"))
    except OSError:
        return removed
    for candidate in candidates:
        if candidate.is_file() and is_stale_partial(candidate):
            with contextlib.suppress(FileNotFoundError):
                candidate.unlink()
                removed.append(candidate)
    return removed


def _new_file_mode() -> int:
    """The mode a plain open() would give a new file (0o666 less the umask)."""
    try:
        with open("/proc/self/status") as fh:
            umask = next(int(line.split()[1], 8) for line in fh if line.startswith("Umask:"))
    except (OSError, StopIteration, ValueError, IndexError):
        umask = os.umask(0o022)
        os.umask(umask)
    return 0o666 & ~umask


@contextlib.contextmanager
def atomic_target(path):
    """Write a file atomically: yields a temporary path in the same directory
    (same suffix, so writers that go by the extension work) that is renamed
    onto ``path`` when the block succeeds and removed when it fails, so an
    interrupted write never leaves a partial file and never loses the old one.
    The file keeps the permissions of the one it replaces (a new one gets
    the umask's).  The temporary file's name holds this process's id and
    host, so a later write in the directory can remove it if the process was
    killed (``remove_stale_partials``)."""
    path = pathlib.Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_partials(path.parent)
    try:
        mode = stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        mode = _new_file_mode()
    try:
        fd, tmp = tempfile.mkstemp(
            dir=path.parent, prefix=f".{path.stem}.{os.getpid()}@{_host()}.", suffix=f".partial{path.suffix}"
        )
    except OSError as exc:  # name the file asked for, not the hidden temporary one
        raise type(exc)(exc.errno, f"cannot write {path.name} into {path.parent}: {exc.strerror}") from None
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)


def atomic_write_bytes(path, data: bytes) -> pathlib.Path:
    """Write bytes to ``path`` atomically (``atomic_target``)."""
    with atomic_target(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return pathlib.Path(path)


def atomic_write_text(path, text: str) -> pathlib.Path:
    """Write text to ``path`` atomically (UTF-8, ``atomic_target``)."""
    return atomic_write_bytes(path, text.encode("utf-8"))
