"""Polarized paint: the full Mueller matrices of ``lut.Paint.mueller`` in a
polarization basis that is continuous over the hemisphere
(``lut.polarized.basis``), and the Mueller LUT of a paint type tabulated in
it (``lut.polarized.mueller_lut``), and a Mitsuba 3 BSDF plugin that renders
it (``register``; ``lut.polarized.mitsuba_bsdf``, which alone imports
mitsuba and drjit, when called).  numpy only otherwise."""

from .basis import mueller_in_transported_basis, stokes_rotation, transported_basis
from .mueller_lut import MuellerLUT, bake_mueller, load_mueller_lut, mueller_lut_path


def register() -> None:
    """Register the Mitsuba 3 BSDF plugin ``germer_paint`` for Mitsuba's
    active (polarized) variant; mitsuba is imported only here
    (``lut.polarized.mitsuba_bsdf``)."""
    from .mitsuba_bsdf import register as _register

    _register()


__all__ = [
    "MuellerLUT",
    "bake_mueller",
    "load_mueller_lut",
    "mueller_in_transported_basis",
    "mueller_lut_path",
    "register",
    "stokes_rotation",
    "transported_basis",
]
