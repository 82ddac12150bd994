"""The add-on's one import of the library, so that no other ``lut`` can
stand in for it.

Blender installs extensions' wheels into one shared site-packages, where a
top-level ``lut`` of another extension could shadow ours.  So the extension
zip (scripts/build_extension.py) ships the library as ``paint_lut_core``;
the repository keeps ``lut`` (tests and scripts import it), and the add-on
run from the repository uses that.  Every add-on module imports the library
from here:

    from ._lut import lut                  # instead of: import lut / import lut.X
    from ._lut import closures, render     # instead of: from lut import closures, render

Submodules load on first use (``from ._lut import X`` is ``lut.X``); the
ones below load with the package, so ``lut.X`` attribute access works."""

from __future__ import annotations

import importlib

#: The library's name inside the extension's wheel.
BUNDLED = "paint_lut_core"

try:
    lut = importlib.import_module(BUNDLED)
except ModuleNotFoundError as error:
    if error.name != BUNDLED:  # the bundled library is there but broken: say so
        raise
    lut = importlib.import_module("lut")

for _name in ("closures", "fitting", "lutfile", "models", "principled", "render"):
    importlib.import_module(f"{lut.__name__}.{_name}")


def __getattr__(name):
    """``from ._lut import X``: the library's submodule X (PEP 562)."""
    if name.startswith("__"):
        raise AttributeError(name)
    try:
        return importlib.import_module(f"{lut.__name__}.{name}")
    except ModuleNotFoundError as error:
        raise AttributeError(f"the paint library has no module {name!r}") from error
