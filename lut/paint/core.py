"""One paint: the paper's incoherent combination of its models (Sec. 4).

    f = facet · f_facet + single · f_single + f_diffuse(ρ)

f_facet is the facet reflection of the exposed interface (Sec. 2.4; under a
smooth interface a mirror, i.e. a delta, exposed by
``Paint.specular_reflectance``), f_single the single volume scattering (Eq. 20
or its rough counterpart) with weight ``single``, and f_diffuse the totally
diffuse term (Eq. 27 or its rough counterpart) of substrate reflectance ρ.

Colour.  ``rho`` and ``single`` are RGB triples in the paint's working space
``space``, or spectra (``lut.colour.management.Spectrum``).  The diffuse term
is non-linear in ρ, f_diffuse(ρ) = ρ(1 - r̄)/(1 - ρ r̄) · f_diffuse(1) (Eq. 27,
and the same factor under a rough interface with its r̄), so an RGB paint
applies that factor per channel, and a spectral paint per wavelength before
integrating to RGB (CIE 1931 2°, D65).  Every other dependence on colour is
linear, so with a non-dispersive n the spectral integral is exact at the cost
of one evaluation of each term's geometry.  A dispersive n (Cauchy
coefficients, spectral paints only) evaluates the geometry per band.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
from typing import Any

import numpy as np

from .. import models
from ..colour import management as cm
from ..models import _validate, fresnel
from ..models.rough import DIFFUSE_NODES, SINGLE_NODES
from .schema import PAINT_FIELDS

#: Band edges [nm] for a dispersive index: the geometry is evaluated at each
#: band's centre wavelength.
DISPERSION_BANDS = np.linspace(380.0, 780.0, 9)

#: The colour-independent angular components of a paint's non-delta BRDF, in
#: the order of ``Paint.components`` and ``Paint.amplitudes``: the facet
#: reflection (unit facet weight), the single-scatter term (unit albedo) and
#: the diffuse term at ρ = 1.
COMPONENTS = ("facet", "single", "diffuse")

#: Wavelength [nm] at which a dispersive paint's index is quoted (sodium D).
REFERENCE_WAVELENGTH = 589.3


def diffuse_amplitude(rho, rbar):
    """k(ρ) = ρ(1 - r̄)/(1 - ρ r̄): the factor of the diffuse term at ρ = 1
    that gives it at ρ (paper Eq. 27; under a rough interface the same
    factor with its r̄, the rough counterpart of Eq. 22).  k(0) = 0, k(1) = 1."""
    rho = np.asarray(rho, dtype=float)
    return rho * (1.0 - rbar) / (1.0 - rho * rbar)


def pigment_of_amplitude(k, rbar):
    """The inverse of ``diffuse_amplitude``: ρ = k/(1 - r̄ + k r̄)."""
    k = np.asarray(k, dtype=float)
    return k / (1.0 - rbar + k * rbar)


@functools.lru_cache(maxsize=64)
def _internal_reflectance(n, slope, distribution, diffuse_nodes):
    """r̄ (Eq. 22, or its rough counterpart), cached: the rough one takes a
    quadrature, and panels and caches ask for it often."""
    if slope > 0.0:
        return models.rough_internal_reflectance(n, slope, distribution, diffuse_nodes)
    return models.internal_reflectance(n)


def _colour_value(value, name: str):
    """An RGB triple (or a grey scalar) in the field's range ([0, 1]), or a
    Spectrum (given as one, as a dataset name or .csv path, or as a dict; see
    Paint.from_dict)."""
    spec = PAINT_FIELDS[name]
    within = spec.allowed.text(name)
    if isinstance(value, (str, dict)):
        value = _colour_from_json(value, name)
    if isinstance(value, cm.Spectrum):
        if not all(spec.allowed.contains(float(v)) for v in value.values):
            raise ValueError(f"{name} spectrum must lie {within} at every wavelength")
        return value
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = (value, value, value)
    try:
        triple = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an RGB triple of numbers {within}, a grey number or a Spectrum") from None
    if len(triple) != 3:
        raise ValueError(f"{name} must be an RGB triple of numbers {within}, got {len(triple)} values")
    for v in triple:
        spec.check(v)
    return triple


def _index(value):
    """n: a number > 0, or Cauchy coefficients (A, B[, C...]) giving
    n(λ) = A + B/λ² + C/λ⁴ + ... with λ in µm."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):  # numpy's scalars too
        return PAINT_FIELDS["n"].check(float(value))
    try:
        coeffs = tuple(float(c) for c in value)
    except (TypeError, ValueError):
        raise ValueError(f"n must be a number > 0 or Cauchy coefficients (A, B, ...), got {value!r}") from None
    if not 1 <= len(coeffs) <= 4 or not all(math.isfinite(c) for c in coeffs):
        raise ValueError("n as Cauchy coefficients must be 1 to 4 finite numbers (A, B, C, D), lambda in um")
    for wl in (0.38, 0.78):
        PAINT_FIELDS["n"].check(_cauchy(coeffs, wl))
    return coeffs if len(coeffs) > 1 else coeffs[0]


def _cauchy(coeffs, wavelength_um):
    return sum(c / wavelength_um ** (2 * k) for k, c in enumerate(coeffs))


def reference_index(n) -> float:
    """The index of a paint type's ``n`` (a number, or Cauchy coefficients as
    stored in a type's JSON) at ``REFERENCE_WAVELENGTH``: the index a
    renderer's single-IOR closures take."""
    if isinstance(n, (int, float)):
        return float(n)
    return float(_cauchy(tuple(n), REFERENCE_WAVELENGTH / 1000.0))


def _field_lines() -> str:
    """The docstring's list of fields, from the schema."""
    lines = []
    for spec in PAINT_FIELDS.values():
        allowed = spec.allowed_text().replace("`", "")
        allowed = f"; {allowed}" if allowed else ""
        lines.append(f"    {spec.name:13} {spec.help}{allowed}; default {spec.default_text()}")
    return "\n".join(lines).lstrip()


#: How each kind of field (``lut.paint.schema.KINDS``) is checked and normalized.
_CHECKS = {
    "index": lambda spec, value: _index(value),
    "colour": lambda spec, value: _colour_value(value, spec.name),
    "number": lambda spec, value: spec.check(value),
    "choice": lambda spec, value: _CHOICES[spec.name](value),
    "text": lambda spec, value: value,  # a label, checked by from_dict
}
_CHOICES = {"distribution": _validate.distribution, "space": cm.working_space}


def _per_channel(term, weight, element):
    """A term's value (shape angles + ``element``) times its RGB weight (3,):
    angles + (3,) + element."""
    return np.expand_dims(term, -1 - len(element)) * np.reshape(
        np.asarray(weight, dtype=float), (3,) + (1,) * len(element)
    )


@dataclasses.dataclass(frozen=True)
class Paint:
    """A paint (paper Sec. 4).  All fields are keywords; see the module
    docstring for how they combine.  The fields (``lut.paint.schema.PAINT_FIELDS``):

    {fields}
    """

    n: Any = PAINT_FIELDS["n"].default
    rho: Any = PAINT_FIELDS["rho"].default
    single: Any = PAINT_FIELDS["single"].default
    g: float = PAINT_FIELDS["g"].default
    slope: float = PAINT_FIELDS["slope"].default
    distribution: str = PAINT_FIELDS["distribution"].default
    facet: float = PAINT_FIELDS["facet"].default
    space: str = PAINT_FIELDS["space"].default
    name: str = PAINT_FIELDS["name"].default

    def __post_init__(self):
        for spec in PAINT_FIELDS.values():
            object.__setattr__(self, spec.name, _CHECKS[spec.kind](spec, getattr(self, spec.name)))
        if self.dispersive and not self.spectral:
            raise ValueError("n as Cauchy coefficients needs a spectral paint (rho or single given as a Spectrum)")
        if self.spectral:
            for key in ("rho", "single"):
                value = getattr(self, key)
                if not isinstance(value, cm.Spectrum) and len(set(value)) != 1:
                    raise ValueError(f"{key} must be a Spectrum or a grey value in a spectral paint, got RGB {value}")

    # ------------------------------------------------------------------ description

    @property
    def spectral(self) -> bool:
        return isinstance(self.rho, cm.Spectrum) or isinstance(self.single, cm.Spectrum)

    @property
    def dispersive(self) -> bool:
        return isinstance(self.n, tuple)

    @property
    def has_single(self) -> bool:
        values = self.single.values if isinstance(self.single, cm.Spectrum) else self.single
        return bool(np.any(np.asarray(values) > 0))

    @property
    def has_diffuse(self) -> bool:
        values = self.rho.values if isinstance(self.rho, cm.Spectrum) else self.rho
        return bool(np.any(np.asarray(values) > 0))

    def type_dict(self) -> dict:
        """What shapes the paint's angular components (``components``): n, g,
        the slope and its distribution.  Colours, the facet weight and the
        working space only scale them (``amplitudes``), so every colour of
        one type shares one LUT.  A dispersive index makes the components
        differ per RGB channel, with weights that depend on the spectra: such
        a paint is a type of its own (its whole description)."""
        if self.dispersive:
            whole = self.to_dict()
            whole.pop("name")
            return whole
        # + 0.0 turns -0.0 into 0.0: equal paints, one key.
        return {"n": self.n + 0.0, "g": self.g + 0.0, "slope": self.slope + 0.0, "distribution": self.distribution}

    def internal_reflectance(self, diffuse_nodes=DIFFUSE_NODES) -> float:
        """r̄ of the paint's interface (Eq. 22, or its rough counterpart) at
        its index (a dispersive one at ``REFERENCE_WAVELENGTH``)."""
        return _internal_reflectance(
            float(self.index_at(REFERENCE_WAVELENGTH)), self.slope, self.distribution, tuple(diffuse_nodes)
        )

    def components(
        self, theta_i, theta_s, phi_s, *, single_nodes=SINGLE_NODES, diffuse_nodes=DIFFUSE_NODES, mueller=False
    ):
        """The colour-independent angular components ``COMPONENTS`` (M00,
        sr⁻¹), shape broadcast(angles) + (T, 3): T = 1 for a non-dispersive
        paint (the same for every channel), T = 3 (one per RGB channel) for a
        dispersive one, whose bands are combined per channel with the
        paint's own weights and divided by ``amplitudes``.  The BRDF is
        Σ_c amplitudes[ch, c] · components[..., ch or 0, c]; a smooth paint's
        facet component is 0 (its mirror is a delta).  ``mueller``: each
        component's whole Mueller matrix (SCATMECH's bases, ``mueller``),
        shape broadcast(angles) + (T, 3, 4, 4)."""
        ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s, broadcast=False)
        shape = np.broadcast_shapes(ti.shape, ts.shape, ps.shape)
        element = (4, 4) if mueller else ()
        tail = (slice(None),) * len(element)
        if not self.dispersive:
            geo = self._geometry(ti, ts, ps, self.n, single_nodes, diffuse_nodes, every_term=True, mueller=mueller)
            out = np.zeros(shape + (1, 3) + element)
            for c, key in enumerate(COMPONENTS):
                if key in geo:
                    out[(..., 0, c, *tail)] = geo[key]
            return out
        out = np.zeros(shape + (3, 3) + element)
        total = np.zeros((3, 3))
        for n, band in self._bands():
            geo = self._geometry(ti, ts, ps, n, single_nodes, diffuse_nodes, every_term=True, mueller=mueller)
            weights = self._weights(geo["rbar"], band)
            for c, key in enumerate(COMPONENTS):
                if key in geo:
                    out[(..., slice(None), c, *tail)] += _per_channel(geo[key], weights[c], element)
                    total[:, c] += weights[c]
        return out / np.where(total > 0, total, 1.0).reshape((3, 3) + (1,) * len(element))

    def amplitudes(self, diffuse_nodes=DIFFUSE_NODES) -> np.ndarray:
        """The weights of the components per RGB channel, (3 channels, 3
        components): the facet weight (times the white of the spectral
        weights for a spectral paint), the single-scatter albedo and k(ρ)
        (``diffuse_amplitude``; a spectrum's k integrated per channel, exact
        because everything else is linear in colour)."""
        if not self.dispersive:
            return np.stack(self._weights(self.internal_reflectance(diffuse_nodes)), axis=1)
        rough = self.slope > 0.0
        total = np.zeros((3, 3))
        for n, band in self._bands():
            rbar = (
                models.rough_internal_reflectance(n, self.slope, self.distribution, diffuse_nodes)
                if rough
                else models.internal_reflectance(n)
            )
            total += np.stack(self._weights(rbar, band), axis=1)
        return total

    def to_dict(self) -> dict:
        """A JSON-able description that ``from_dict`` turns back into an
        equal paint; spectra are stored as their sampled values."""

        def colour(v):
            if isinstance(v, cm.Spectrum):
                return {"spectrum": v.name, "wavelengths": cm.WAVELENGTHS.tolist(), "values": v.key()}
            return list(v)

        return {
            "n": list(self.n) if self.dispersive else self.n,
            "rho": colour(self.rho),
            "single": colour(self.single),
            "g": self.g,
            "slope": self.slope,
            "distribution": self.distribution,
            "facet": self.facet,
            "space": self.space,
            "name": self.name,
        }

    @classmethod
    def from_dict(cls, data: dict) -> Paint:
        """A paint from a dict as written by ``to_dict`` or by hand (JSON or
        TOML): colours may be numbers, RGB lists, a spectrum dataset name
        ``"ColorChecker N Ohta/red"``, a .csv path, or
        {"wavelengths": [...], "values": [...]} (optionally with "scale")."""
        if not isinstance(data, dict):
            raise ValueError("a paint description must be a table/object of fields")
        fields = set(PAINT_FIELDS)
        unknown = set(map(str, data)) - fields
        if unknown:
            raise ValueError(
                f"unknown paint field(s) {', '.join(sorted(unknown))}; fields are {', '.join(sorted(fields))}"
            )
        kw = dict(data)
        if isinstance(kw.get("n"), list):
            kw["n"] = tuple(kw["n"])
        if "name" in kw and not isinstance(kw["name"], str):
            raise ValueError(f"name must be text, got {kw['name']!r}")
        try:
            return cls(**kw)
        except TypeError as exc:  # a value of a kind no field takes (null, a table...)
            raise ValueError(f"invalid paint description: {exc}") from None

    def index_at(self, wavelength_nm):
        """n at a wavelength [nm]."""
        if self.dispersive:
            return _cauchy(self.n, np.asarray(wavelength_nm) / 1000.0)
        return self.n

    def converted(self, space: str) -> Paint:
        """The same paint with results in another working space (RGB colour
        values converted linearly, Bradford adaptation: colour-science's matrices)."""
        space = cm.working_space(space)
        if space == self.space:
            return self
        matrix = cm.rgb_to_rgb(self.space, space)

        def conv(v):
            if isinstance(v, cm.Spectrum):
                return v
            return tuple(float(x) for x in np.clip(matrix @ np.array(v), 0.0, 1.0))

        return dataclasses.replace(self, rho=conv(self.rho), single=conv(self.single), space=space)

    # ------------------------------------------------------------------ evaluation

    def _geometry(self, ti, ts, ps, n, single_nodes, diffuse_nodes, every_term=False, mueller=False):
        """M00 of each term (its whole Mueller matrix with ``mueller``) with
        unit weights (the diffuse one at ρ = 1) and the interface's r̄.
        Zero-weight terms are not computed unless ``every_term``; smooth
        paints never run the rough models."""
        out = {}
        rough = self.slope > 0.0
        if (self.facet > 0.0 or every_term) and rough:
            out["facet"] = models.facet_reflection(
                ti, ts, ps, n=n, slope=self.slope, distribution=self.distribution, mueller=mueller
            )
        if self.has_single or every_term:
            if rough:
                out["single"] = models.rough_single(
                    ti, ts, ps, n=n, g=self.g, slope=self.slope, distribution=self.distribution,
                    mueller=mueller, nodes=single_nodes,
                )  # fmt: skip
            else:
                out["single"] = models.smooth_single(ti, ts, ps, n=n, g=self.g, mueller=mueller)
        if self.has_diffuse or every_term:
            if rough:
                out["diffuse"] = models.rough_diffuse(
                    ti, ts, ps, n=n, rho=1.0, slope=self.slope, distribution=self.distribution,
                    mueller=mueller, nodes=diffuse_nodes,
                )  # fmt: skip
                out["rbar"] = models.rough_internal_reflectance(n, self.slope, self.distribution, diffuse_nodes)
            else:
                out["diffuse"] = models.smooth_diffuse(ti, ts, ps, n=n, rho=1.0, mueller=mueller)
                out["rbar"] = models.internal_reflectance(n)
        return out

    def _weights(self, rbar, band=slice(None)):
        """RGB weights of the terms: (facet, single, diffuse) as (3,) arrays,
        integrating spectra over the wavelengths of ``band``."""
        if self.spectral:
            w = cm.spectral_weights(self.space)[:, band]
            single = (
                self.single.values[band]
                if isinstance(self.single, cm.Spectrum)
                else np.full(w.shape[1], self.single[0])
            )
            rho = self.rho.values[band] if isinstance(self.rho, cm.Spectrum) else np.full(w.shape[1], self.rho[0])
            return self.facet * w.sum(axis=1), w @ single, w @ diffuse_amplitude(rho, rbar)
        return np.full(3, self.facet), np.asarray(self.single, dtype=float), diffuse_amplitude(self.rho, rbar)

    def _bands(self):
        """(n, wavelength selection) per evaluation of the geometry."""
        if not self.dispersive:
            return [(self.n, slice(None))]
        centres = 0.5 * (DISPERSION_BANDS[:-1] + DISPERSION_BANDS[1:])
        which = np.clip(np.searchsorted(DISPERSION_BANDS, cm.WAVELENGTHS, side="right") - 1, 0, len(centres) - 1)
        return [(float(self.index_at(c)), which == b) for b, c in enumerate(centres)]

    def brdf(self, theta_i, theta_s, phi_s, *, single_nodes=SINGLE_NODES, diffuse_nodes=DIFFUSE_NODES):
        """Polarization-averaged RGB BRDF [sr⁻¹] of all non-delta terms, shape
        broadcast(angles) + (3,), in the paint's working space.  Angles as in
        ``lut.models`` (radians; source at azimuth π)."""
        return self._weighted_terms(theta_i, theta_s, phi_s, single_nodes, diffuse_nodes, mueller=False)

    def mueller(self, theta_i, theta_s, phi_s, *, single_nodes=SINGLE_NODES, diffuse_nodes=DIFFUSE_NODES):
        """Mueller BRDF [sr⁻¹] of all non-delta terms per RGB channel, shape
        broadcast(angles) + (3, 4, 4), in SCATMECH's s/p bases (``lut.models``,
        docs/models.md): the models' Mueller matrices weighted as in ``brdf``,
        whose values are its [..., 0, 0] elements."""
        return self._weighted_terms(theta_i, theta_s, phi_s, single_nodes, diffuse_nodes, mueller=True)

    def _weighted_terms(self, theta_i, theta_s, phi_s, single_nodes, diffuse_nodes, mueller):
        """Σ over bands and terms of the term's RGB weight times its M00
        (shape angles + (3,)) or its Mueller matrix (angles + (3, 4, 4)); only
        terms of non-zero weight are computed."""
        ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s, broadcast=False)
        element = (4, 4) if mueller else ()
        out = np.zeros(np.broadcast_shapes(ti.shape, ts.shape, ps.shape) + (3,) + element)
        for n, band in self._bands():
            geo = self._geometry(ti, ts, ps, n, single_nodes, diffuse_nodes, mueller=mueller)
            for key, weight in zip(COMPONENTS, self._weights(geo.get("rbar", 0.0), band), strict=True):
                if key in geo:
                    out += _per_channel(geo[key], weight, element)
        return out

    def specular_reflectance(self, theta_i):
        """RGB reflectance of the smooth interface's mirror reflection (a
        delta in the BRDF): facet · ½(|r_s|² + |r_p|²) at θi, shape
        theta_i.shape + (3,).  Zero for rough paints, whose interface
        reflection is the facet lobe inside ``brdf``."""
        ti = _validate.polar_angle(theta_i, "theta_i")
        out = np.zeros(ti.shape + (3,))
        if self.slope > 0.0 or self.facet == 0.0:
            return out
        up = ti < np.pi / 2
        cos_i = np.where(up, np.cos(ti), 0.0)
        for n, band in self._bands():
            rs, rp = fresnel.reflection_coefficients(cos_i, n)
            refl = np.where(up, 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2), 0.0)
            white = cm.spectral_weights(self.space)[:, band].sum(axis=1) if self.spectral else np.ones(3)
            out += refl[..., None] * self.facet * white
        return out


if Paint.__doc__:  # not under python -OO
    Paint.__doc__ = Paint.__doc__.format(fields=_field_lines())


def _colour_from_json(value, name):
    """A Spectrum from its JSON/TOML form; errors name the parameter."""
    try:
        if isinstance(value, dict):
            unknown = set(value) - {"spectrum", "wavelengths", "values", "scale"}
            if unknown:
                raise ValueError(
                    f"unknown spectrum field(s) {', '.join(sorted(map(str, unknown)))}; "
                    "fields are spectrum, wavelengths, values, scale"
                )
            scale = value.get("scale", 1.0)
            if "wavelengths" in value and "values" in value:
                label = value.get("spectrum")
                if label is not None and not isinstance(label, str):
                    raise ValueError(f"'spectrum' (the name) must be text, got {label!r}")
                return cm.Spectrum(value["wavelengths"], value["values"], name=label, scale=scale)
            if isinstance(value.get("spectrum"), str):
                return cm.Spectrum(value["spectrum"], scale=scale)
            raise ValueError("a spectrum needs 'wavelengths' and 'values', or 'spectrum' naming a dataset or .csv")
        return cm.Spectrum(value)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None
