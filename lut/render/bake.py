"""One operation for everything a renderer needs of a paint: its type's LUT
and the closure fit of every render target (``bake_for_render``), with
progress and cancellation over the whole of it; and the values a node group
takes for a paint's colours (``node_inputs``).

Used by the Blender add-on's operator, its headless API and batch baking
alike; numpy only."""

from __future__ import annotations

import dataclasses
import pathlib

import numpy as np

from ..lutfiles import baking
from ..lutfiles import format as lutfile
from ..paint.core import Paint, diffuse_amplitude, pigment_of_amplitude
from . import closures, fitting

#: Share of the progress bar taken by the LUT (the fits take the rest).
LUT_SHARE = 0.7
#: The name of Cycles' OSL variant among a bake's fits and errors
#: (``RenderBake.variants``; its goals are ``measure.GOALS["OSL"]``).
OSL_VARIANT = "OSL"


@dataclasses.dataclass
class RenderBake:
    """The result of ``bake_for_render``: the LUT, its loaded content, and
    per target the fit and its weights file; ``computed`` lists what was
    computed (the rest came from valid cached files).  ``osl`` and
    ``osl_path``: Cycles' OSL variant (``lut.render.fitting.fit_osl``) and
    its weights file, where asked for (else None)."""

    lut_path: pathlib.Path
    lut: baking.LUT
    fits: dict
    fit_paths: dict
    computed: list
    osl: fitting.Fit | None = None
    osl_path: pathlib.Path | None = None

    @property
    def key(self) -> str:
        """The paint type's cache key (shared by every colour of the type)."""
        return self.lut.key

    def errors(self, paint: Paint) -> dict:
        """{target: the error each fit reports for this paint (``Fit.error``:
        the fidelity measure, ``lut.render.measure``, over its whole grid)}."""
        return {target: whole for target, (whole, _) in self.all_errors(paint).items()}

    def grazing_errors(self, paint: Paint) -> dict:
        """{target: the fidelity measure each fit reports for this paint over
        the grazing band, θl >= 60° (``Fit.grazing_error``)}."""
        return {target: band for target, (_, band) in self.all_errors(paint).items()}

    @property
    def drawn_osl(self) -> fitting.Fit | None:
        """The OSL variant where its ramps carry weight (``Fit.draws_ramps``),
        else None: a variant whose ramps did not pay renders as the SVM fit."""
        return self.osl if self.osl is not None and self.osl.draws_ramps else None

    def variants(self) -> dict:
        """{name: fit}: each target's fit, and Cycles' OSL variant as "OSL"
        where it was baked (``OSL_VARIANT``)."""
        return {**self.fits, **({OSL_VARIANT: self.osl} if self.osl is not None else {})}

    def all_errors(self, paint: Paint) -> dict:
        """{target: (whole, grazing band)}: the fidelity measure each fit
        reports for this paint (``lut.render.fitting.reported_errors``),
        the OSL variant's as "OSL" where it was baked."""
        amps = self.lut.amplitudes(paint)
        return {target: fitting.reported_errors(fit.grams(), amps) for target, fit in self.variants().items()}


def _cached_fit(path, lut, target, exact_metallic, calibration, eevee_mode="EXACT", osl=False, base=None):
    """The fit stored at ``path`` if it is valid and belongs to this LUT,
    target, calibration, EEVEE mode and variant (SVM or OSL; an OSL
    variant to the SVM fit ``base`` it is made from), else None."""
    if not pathlib.Path(path).exists():
        return None
    try:
        fitted = fitting.read_fit(path)
    except lutfile.LUTError:
        return None
    if fitted.lut_key != lut.key or fitted.target != target or fitted.exact_metallic != exact_metallic:
        return None
    if fitted.calibration != calibration or fitted.eevee_mode != eevee_mode or fitted.osl != osl:
        return None
    if fitted.stale_goals:
        return None  # chosen against EEVEE's goals of an earlier release: fitted again
    if base is not None and fitted.base_key != fitting.content_key(base):
        return None
    if osl and [c for c in fitted.closures if c.osl] != closures.ramp_closures(
        fitting.OSL_EXPONENTS, fitting.OSL_RETRO
    ):
        return None  # a variant of other ramps (an earlier release's): fitted again
    return fitted


def _identity(path):
    """What tells a file from the one written over it (writes are atomic
    renames: a new inode), or None when there is none."""
    try:
        stat = path.stat()
    except FileNotFoundError:
        return None
    return stat.st_ino, stat.st_mtime_ns, stat.st_size


def bake_for_render(
    paint: Paint,
    directory,
    *,
    targets=closures.TARGETS,
    exact_metallic=True,
    eevee_calibration=None,
    eevee_mode=fitting.DEFAULT_EEVEE_MODE,
    osl=False,
    force=False,
    progress=None,
    **lut_options,
) -> RenderBake:
    """Bake the paint's type LUT (``lut.bake``) and fit it for each render
    target (``lut.render.fitting.fit_lut``), writing the weights files beside it;
    valid cached files are reused unless ``force``.  ``eevee_calibration``:
    the Blender line whose measured EEVEE closure responses the EEVEE fit
    uses (``lut.render.eevee.calibration_for(bpy.app.version)``; None: Cycles'
    formulas); ``eevee_mode``: "EXACT" or "CONVERGED"
    (``lut.render.fitting.EEVEE_MODES``); ``osl``: also Cycles' OSL variant
    (``lut.render.fitting.fit_osl``, from the Cycles fit; Cycles must be a
    target), as ``RenderBake.osl``.  ``progress(fraction)``
    (0..1) is called throughout and may raise to cancel: files already
    complete stay (they are valid caches), nothing is half-written."""
    targets = [closures.validate_target(t) for t in targets]
    if osl and "CYCLES" not in targets:
        raise ValueError(f"osl=True needs 'CYCLES' among the targets, got {targets!r}")
    eevee_mode = fitting.validate_eevee_mode(eevee_mode)
    report = progress or (lambda fraction: None)
    computed = []
    path = baking.lut_path(paint, directory, **lut_options)
    before = _identity(path)
    path = baking.bake(
        paint, directory, force=force, progress=lambda done, total: report(LUT_SHARE * done / max(total, 1)),
        **lut_options,
    )  # fmt: skip
    table = baking.load_lut(path)
    if force or before is None or _identity(path) != before:  # a damaged file baked again is computed too
        computed.append("lut")
    report(LUT_SHARE)
    fits, paths, todo = {}, {}, {}
    for target in targets:
        calibration = tuple(eevee_calibration) if (target == "EEVEE" and eevee_calibration) else None
        mode = eevee_mode if target == "EEVEE" else "EXACT"
        paths[target] = fitting.fit_path(path, target, exact_metallic, calibration, mode)
        fitted = None if force else _cached_fit(paths[target], table, target, exact_metallic, calibration, mode)
        if fitted is None:
            todo[target] = (calibration, mode)
        else:
            fits[target] = fitted
    # The engines' fits run one after the other on this thread: their work
    # is many small least-squares steps that hold the interpreter lock, so
    # two threads took 0.1-0.25 s longer than one (a rough type, 2 cores).
    for target, (calibration, mode) in todo.items():
        fits[target] = fitting.fit_lut(
            table, target, exact_metallic=exact_metallic, calibration=calibration, eevee_mode=mode
        )  # fmt: skip
        fitting.write_fit(fits[target], paths[target])
        computed.append(target)
        report(LUT_SHARE + (1.0 - LUT_SHARE) * len(fits) / len(targets))
    fits = {target: fits[target] for target in targets}
    variant = variant_path = None
    if osl:
        variant_path = fitting.fit_path(path, "CYCLES", exact_metallic, osl=True)
        variant = None if force else _cached_fit(
            variant_path, table, "CYCLES", exact_metallic, None, osl=True, base=fits["CYCLES"]
        )  # fmt: skip
        if variant is None:
            variant = fitting.fit_osl(table, fits["CYCLES"])
            fitting.write_fit(variant, variant_path)
            computed.append(OSL_VARIANT)
    computed.sort(key=lambda name: ["lut", *targets, OSL_VARIANT].index(name))
    report(1.0)
    return RenderBake(path, table, fits, paths, computed, variant, variant_path)


def load_baked(
    lut_path, *, targets=closures.TARGETS, exact_metallic=True, eevee_calibration=None,
    eevee_mode=fitting.DEFAULT_EEVEE_MODE, osl=False,
) -> RenderBake:  # fmt: skip
    """The ``RenderBake`` of a LUT already baked at ``lut_path`` and its
    targets' fits (the options as for ``bake_for_render``), from their
    files; Cycles' OSL variant (``osl``) is made from the Cycles fit where
    it has no valid file of that fit yet (about 0.3 s).  Raises lut.LUTError
    where the LUT or a fit is missing, damaged or of another bake."""
    path = pathlib.Path(lut_path)
    targets = [closures.validate_target(t) for t in targets]
    eevee_mode = fitting.validate_eevee_mode(eevee_mode)
    table = baking.load_lut(path)
    fits, paths, computed = {}, {}, []
    for target in targets:
        calibration = tuple(eevee_calibration) if (target == "EEVEE" and eevee_calibration) else None
        mode = eevee_mode if target == "EEVEE" else "EXACT"
        paths[target] = fitting.fit_path(path, target, exact_metallic, calibration, mode)
        fits[target] = _cached_fit(paths[target], table, target, exact_metallic, calibration, mode)
        if fits[target] is None:
            raise lutfile.LUTError(f"{paths[target]}: no valid {target} fit of {path.name}: bake the paint")
    variant = variant_path = None
    if osl and "CYCLES" in fits:
        variant_path = fitting.fit_path(path, "CYCLES", exact_metallic, osl=True)
        variant = _cached_fit(variant_path, table, "CYCLES", exact_metallic, None, osl=True, base=fits["CYCLES"])
        if variant is None:
            variant = fitting.fit_osl(table, fits["CYCLES"])
            fitting.write_fit(variant, variant_path)
            computed.append(OSL_VARIANT)
    return RenderBake(path, table, fits, paths, computed, variant, variant_path)


def node_inputs(paint: Paint, internal_reflectance: float | None = None) -> dict:
    """The node group inputs that render ``paint``: "Pigment Color" (the RGB
    ρ whose diffuse amplitude k(ρ) is the paint's; for an RGB paint ρ itself,
    for a spectral one the ρ that gives the spectrally integrated k exactly),
    "Single Scattering Color" and "Surface Reflection".  ``internal_reflectance``
    (r̄ of the type; computed when not given) is what the group computes k with."""
    rbar = paint.internal_reflectance() if internal_reflectance is None else internal_reflectance
    if paint.spectral or paint.dispersive:
        amps = paint.amplitudes()
        pigment = pigment_of_amplitude(np.clip(amps[:, 2], 0.0, 1.0), rbar)
        single = amps[:, 1]
        facet = float(np.mean(amps[:, 0]))
    else:
        pigment, single, facet = np.asarray(paint.rho, dtype=float), np.asarray(paint.single), paint.facet
    return {
        "Pigment Color": tuple(float(v) for v in np.clip(pigment, 0.0, 1.0)),
        "Single Scattering Color": tuple(float(v) for v in single),
        "Surface Reflection": float(facet),
    }


def amplitudes_of_inputs(inputs: dict, internal_reflectance: float) -> np.ndarray:
    """(3 channels, 3 components) amplitudes a node group computes from its
    inputs: the facet weight, the single-scatter colour and k(ρ)."""
    rho = np.asarray(inputs["Pigment Color"], dtype=float)
    return np.stack(
        [
            np.full(3, float(inputs["Surface Reflection"])),
            np.asarray(inputs["Single Scattering Color"], dtype=float),
            diffuse_amplitude(rho, internal_reflectance),
        ],
        axis=1,
    )


def diffuse_albedo(table) -> float:
    """a_D: the directional-hemispherical reflectance at normal incidence of
    the diffuse component at ρ = 1 (∫ B_D(0, θs, φs) cos θs dω), from a
    loaded LUT; for a smooth interface 1 - R(0) (all light that enters comes
    out when nothing is absorbed), less for a rough one.  The diffuse colour
    an artist sees head-on is k(ρ)·a_D."""
    x, w = np.polynomial.legendre.leggauss(48)
    theta = 0.25 * np.pi * (x + 1.0)
    weights = 0.25 * np.pi * w * np.cos(theta) * np.sin(theta)
    phi = (np.arange(24) + 0.5) * 2 * np.pi / 24 - np.pi
    comps = table.components(0.0, theta[:, None], phi[None, :])[..., 0, 2]  # (θ, φ): the diffuse component
    return float(np.sum(comps.mean(axis=1) * weights) * 2 * np.pi)


def pigment_of_seen(colour, albedo: float, internal_reflectance: float) -> np.ndarray:
    """The pigment ρ whose diffuse colour seen head-on is ``colour``: k =
    colour/a_D, ρ = k/(1 - r̄ + k r̄); colours beyond a_D (what ρ = 1 gives)
    are limited to it."""
    k = np.clip(np.asarray(colour, dtype=float) / albedo, 0.0, 1.0)
    return pigment_of_amplitude(k, internal_reflectance)


def seen_of_pigment(rho, albedo: float, internal_reflectance: float) -> np.ndarray:
    """The diffuse colour seen head-on of a pigment ρ: k(ρ)·a_D."""
    return diffuse_amplitude(rho, internal_reflectance) * albedo
