"""Bake the paint materials of .blend files headless, for pipelines and farms.

    .venv/bin/python scripts/batch_bake.py SCENE.blend [more.blend ...] [--force] [--pack]
                                           [--report FILE] [--jobs N]
    blender -b --factory-startup -P scripts/batch_bake.py -- SCENE.blend ... [options]

Per file: open it, bake the paint materials its objects use, skip unused and
up-to-date ones (the LUT cache), save it atomically.  Writes a JSON report
(--report) and prints a summary; exits 1 if any file or material failed (or
a linked material's library holds no current bake), 2 on bad arguments (an
unwritable --report is found before any work).

The command itself is ``addon.batch.main``, which the extension ships; this
file runs it from the repository."""

from __future__ import annotations

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon import batch  # noqa: E402

if __name__ == "__main__":
    sys.exit(batch.main(script=__file__))  # Blender too exits with this code after -P
