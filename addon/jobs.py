"""Background bakes: lut.bake on a worker thread, with progress and
cancellation, so the interface never blocks.  Pure Python (no bpy), so it is
tested without a window."""

from __future__ import annotations

import threading

import lut
from lut import closures


class Cancelled(Exception):
    """Raised inside the worker to stop a bake; nothing is written."""


class BakeJob:
    """Bake one paint on a thread.  ``progress`` (0..1), ``done``,
    ``path`` and ``fits`` (on success: lut.closures.fit_for_lut's),
    ``error`` (a message) and ``cancel()``."""

    def __init__(self, paint: lut.Paint, directory, exact_metallic=True, **options):
        self.paint, self.directory, self.options = paint, directory, options
        self.exact_metallic = exact_metallic
        self.progress = 0.0
        self.path = None
        self.fits = None
        self.error = None
        self._cancel = threading.Event()
        self._thread = threading.Thread(target=self._run, name="paint-lut-bake", daemon=True)

    def start(self):
        self._thread.start()
        return self

    def cancel(self):
        self._cancel.set()

    @property
    def done(self) -> bool:
        return self._thread.ident is not None and not self._thread.is_alive()

    @property
    def cancelled(self) -> bool:
        return self._cancel.is_set()

    def wait(self, timeout=None):
        self._thread.join(timeout)
        return self.done

    def _progress(self, done, total):
        if self._cancel.is_set():
            raise Cancelled
        self.progress = done / total if total else 1.0

    def _run(self):
        try:
            path = lut.bake(self.paint, self.directory, progress=self._progress, **self.options)
            self.fits = closures.fit_for_lut(self.paint, path, exact_metallic=self.exact_metallic)
            self.path = path
            self.progress = 1.0
        except Cancelled:
            self.error = "cancelled"
        except (ValueError, OSError) as exc:
            self.error = str(exc)
