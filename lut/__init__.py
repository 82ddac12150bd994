"""Paint LUT: physically based paint appearance from Germer's scattering models.

``lut.models`` holds the paper's models; ``lut.Paint`` combines them into a
paint; ``lut.bake`` writes a paint's LUT file and ``lut.load_lut`` reads it."""

__version__ = "0.1.0"

from .baking import LUT, bake, describe, load_lut, lut_path  # noqa: E402
from .colour_management import Spectrum  # noqa: E402
from .lutfile import LUTError  # noqa: E402
from .paint import Paint  # noqa: E402
from .presets import PRESETS, preset  # noqa: E402

__all__ = ["LUT", "LUTError", "PRESETS", "Paint", "Spectrum", "bake", "describe", "load_lut", "lut_path", "preset"]
