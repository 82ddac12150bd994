"""The render fit: a paint type's LUT turned into Blender closures.
``closures`` holds the closure kinds and their formulas, ``nnls`` the
non-negative least squares, ``fitting`` the fit and its reported error,
``eevee`` (with ``eevee_tables``) EEVEE's measured closure responses,
``principled`` the Principled BSDF fallback that exporters read, and
``bake`` the one operation a renderer calls (``bake_for_render``).

Owns how a LUT is drawn by a renderer.  May import every layer below it
(``lut.models``, ``lut.colour``, ``lut.paint``, ``lut.lutfiles``); only the
add-on builds on it."""

import importlib
import warnings

from . import bake, closures, eevee, fitting, nnls, principled

__all__ = ["bake", "closures", "eevee", "fitting", "nnls", "principled"]

#: Names of the module ``lut.render`` was before the library was layered
#: (now ``lut.render.bake``): kept for one release, with a warning.
_FORMER = ("RenderBake", "LUT_SHARE", "bake_for_render", "node_inputs", "amplitudes_of_inputs", "diffuse_albedo")
_FORMER += ("pigment_of_seen", "seen_of_pigment")


def __getattr__(name):
    """``lut.render.bake_for_render`` and the other names of the former
    module: ``lut.render.bake``'s, with a DeprecationWarning (PEP 562)."""
    if name in _FORMER:
        warnings.warn(f"{__name__}.{name} is deprecated: use {__name__}.bake.{name}", DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(f"{__name__}.bake"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
