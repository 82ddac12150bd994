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
