"""Polarized paint: the full Mueller matrices of ``lut.Paint.mueller`` in a
polarization basis that is continuous over the whole hemisphere
(``lut.polarized.basis``), the basis a tabulated Mueller matrix and a
polarized renderer can share.  numpy only."""

from .basis import mueller_in_transported_basis, stokes_rotation, transported_basis

__all__ = ["mueller_in_transported_basis", "stokes_rotation", "transported_basis"]
