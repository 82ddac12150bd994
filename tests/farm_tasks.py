"""A phase 2 task for the farm's tests (``lut.farm.run(bake=...)``),
importable by Dask's worker processes: it has no Blender and no fixtures."""

from __future__ import annotations

import os
import pathlib
import signal
import threading
import time

from lut import farm


def bake_killed_once(spec, store, force=False):
    """``lut.farm.bake_type``, but the first call of the run starts the bake
    and SIGKILLs its own worker process a moment later, mid-bake (a marker
    file in the store says the kill happened; the task's next try bakes)."""
    marker = pathlib.Path(store) / "killed-once"
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return farm.bake_type(spec, store, force)
    os.write(fd, str(os.getpid()).encode())
    os.close(fd)
    threading.Thread(target=farm.bake_type, args=(spec, store, force), daemon=True).start()
    time.sleep(0.3)  # into the LUT's tabulation
    os.kill(os.getpid(), signal.SIGKILL)
    return None  # not reached


def crash_on(name: str, argv: list) -> None:
    """A Blender child that dies of a segmentation fault when it is given a
    file called ``name``, and is ``addon.batch`` otherwise (run as a script:
    ``python farm_tasks.py NAME ARGS...``)."""
    if any(pathlib.Path(a).name == name for a in argv):
        os.kill(os.getpid(), signal.SIGSEGV)
    import bpy  # noqa: F401  (before the add-on, as batch.child_command does)

    from addon import batch

    raise SystemExit(batch.main(argv))


if __name__ == "__main__":
    import sys

    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
    crash_on(sys.argv[1], sys.argv[2:])
