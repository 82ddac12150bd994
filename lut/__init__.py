"""Paint LUT: physically based paint appearance from Germer's scattering models.

The library is in layers, each a subpackage that imports only the layers
before it:

1. ``lut.models``: the paper's models, as Mueller matrices (numpy only);
2. ``lut.colour``: spectra and working spaces;
3. ``lut.paint``: a paint (``lut.Paint``), its fields and the named paints;
4. ``lut.lutfiles``: a paint type's LUT, baked (``lut.bake``), cached and
   read back (``lut.load_lut``);
5. ``lut.render``: the LUT fitted onto Blender closures for each engine.

At the top: this module's names, the command line (``python -m lut``), the
example, the benchmarks and the figures.  The Blender add-on builds on
``lut``; ``lut`` never imports it, nor ``bpy``."""

__version__ = "0.1.0"

from . import (
    _former,  # noqa: E402
    colour,  # noqa: E402
    lutfiles,  # noqa: E402
    models,  # noqa: E402
    paint,  # noqa: E402
    render,  # noqa: E402
)
from .colour.management import Spectrum  # noqa: E402
from .lutfiles.baking import LUT, bake, describe, load_lut, lut_path  # noqa: E402
from .lutfiles.format import LUTError  # noqa: E402
from .paint.core import Paint  # noqa: E402
from .paint.presets import PRESETS, preset  # noqa: E402

__all__ = ["LUT", "LUTError", "PRESETS", "Paint", "Spectrum", "bake", "describe", "load_lut", "lut_path", "preset"]
__all__ += ["models", "colour", "paint", "lutfiles", "render"]  # the layers

_former.install(__name__)


def __getattr__(name):
    """``lut.fitting`` and the library's other former module names: the
    module at its new path, with a DeprecationWarning (PEP 562)."""
    if name in _former.FORMER:
        import importlib

        module = globals()[name] = importlib.import_module(_former.warn(__name__, name))
        return module
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
