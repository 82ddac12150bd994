"""Polarized paint: the full Mueller matrices of ``lut.Paint.mueller`` in a
polarization basis that is continuous over the hemisphere
(``lut.polarized.basis``), and the Mueller LUT of a paint type tabulated in
it (``lut.polarized.mueller_lut``).  numpy only."""

from .basis import mueller_in_transported_basis, stokes_rotation, transported_basis
from .mueller_lut import MuellerLUT, bake_mueller, load_mueller_lut, mueller_lut_path

__all__ = [
    "MuellerLUT",
    "bake_mueller",
    "load_mueller_lut",
    "mueller_in_transported_basis",
    "mueller_lut_path",
    "stokes_rotation",
    "transported_basis",
]
