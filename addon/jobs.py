"""Background bakes: ``lut.render.bake.bake_for_render`` (the paint type's LUT and
every engine's fit) on a worker thread, with progress and cancellation over
the whole of it, so the interface never blocks.  Pure Python (no bpy), so it
is tested without a window."""

from __future__ import annotations

import threading

from ._lut import closures, lut, render_bake


class Cancelled(Exception):
    """Raised inside the worker to stop a bake; nothing is half-written."""


class BakeJob:
    """Bake one paint on a thread.  ``progress`` (0..1), ``done``,
    ``result`` (on success: the ``lut.render.bake.RenderBake``), ``error`` (a
    message) and ``cancel()``."""

    def __init__(self, paint: lut.Paint, directory, exact_metallic=True, targets=closures.TARGETS, **options):
        self.paint, self.directory, self.options = paint, directory, options
        self.exact_metallic = exact_metallic
        self.targets = targets
        self.progress = 0.0
        self.result = None
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

    def _progress(self, fraction):
        if self._cancel.is_set():
            raise Cancelled
        self.progress = fraction

    def _run(self):
        try:
            result = render_bake.bake_for_render(
                self.paint, self.directory, targets=self.targets, exact_metallic=self.exact_metallic,
                progress=self._progress, **self.options,
            )  # fmt: skip
            if self._cancel.is_set():  # cancelled after the last step: the result is not used
                raise Cancelled
            self.result = result
            self.progress = 1.0
        except Cancelled:
            self.error = "cancelled"
        except (ValueError, OSError) as exc:
            self.error = str(exc) or type(exc).__name__
