"""The Mueller LUT of a paint type: each colour-free component's whole
Mueller matrix (``lut.Paint.components(..., mueller=True)``: facet, single
scattering, diffuse at ρ = 1; the smooth interface's mirror stays a delta),
tabulated in the transported polarization bases (``lut.polarized.basis``),
written and cached like the M00 LUT (``lut.lutfiles``).

**Parameterization.** Rusinkiewicz's half/difference angles as in the M00
LUT (``lut.lutfiles.angles``, ``lut.lutfiles.table``): θh = (π/2)u², θd
uniform, and each node is placed in the *half frame*, the frame whose x
axis lies under the half vector (φh = 0).  The incident and exit rays of a
node are smooth functions of (u, θd, φd) there, and so are their
transported bases: every element is smooth over the table, the normal
included, where SCATMECH's bases turn with the azimuth.  Only mirror
symmetry folds φd: the mirror image of a configuration in the plane
through the normal and the half vector has the matrix D·M·D, D = diag(1, 1,
-1, -1) (U and V change sign: the transported basis's s is mirrored with
its ray, p = k×s is mirrored and reversed), so φd runs over [0, π].
(Reciprocity would fold it to [0, π/2] but exchanges the rays, whose
bases differ.)

**What a node holds.**  M00 times (cos θi·cos θs)^p, with p per component
(``cos_power``) such that the product stays smooth up to the horizon: p = 1
for the facet term, whose M00 grows like 1/(cos θi cos θs) there (the M00
LUT's G); p = -1 for single scattering and the diffuse term under a smooth
interface, which fade like the Fresnel transmittances (like cos θ); p = 0
under a rough one, where they stay finite.  The other elements are stored
*normalised*, Mij/M00 (within [-1, 1], 0 where M00 is 0).  A lobe's M00
changes by orders of magnitude across a few cells while the state of
polarization it leaves light in changes slowly, so the two are interpolated
apart and multiplied: interpolating each Mij·cos θi·cos θs apart left errors
of Mij/M00 four times larger on smooth paints.

**Below the horizon** a node holds the values continued past it by their
point reflection there (``horizon_terms``: f(θ) = 2 f(π/2) - f(π - θ), ray by
ray), which keeps a cell straddling the horizon accurate to second order.
Holding the matrix at 89° instead (the M00 LUT's clamp) left M00 off by up
to 2.5 times with a ray beyond 85° (27% RMS on smooth paints), Mij/M00 by
up to 0.12.

**Quadrature.**  Single scattering is baked with the models' own
(``lut.models.rough``'s ``SINGLE_NODES``), not the M00 LUT's coarser one:
the polarization of a rough paint's single scattering converges more slowly
than its M00 (with (3, 4) nodes Mij/M00 is off by up to 0.024 at θi = 66°,
0.003 with (4, 6), against (12, 18)).

**The facet term** (``closed_facet``) is a closed form (paper Sec. 2.4,
Eqs. 35-38: ``lut.models.facet_reflection``).  The table holds it, but its
peak on a near-smooth rough paint is sharper than the table's cells (M00
errors of several per cent near the mirror), so the Mitsuba plugin
evaluates it from the closed form, and so does the lookup here by default
for a type with one n; a dispersive type's (one tile per channel) comes
from the table.

**Lookup** (``MuellerLUT.components``): the geometry is taken into its
half frame, its φd folded (and D applied), every stored value interpolated
trilinearly, M00 freed of its cos power and the normalised elements
multiplied by it, and the matrix turned from the half frame's transported
bases into those of the models' frame (the source at azimuth π) by one
Stokes rotation per ray.

**Image layout.** float32, three channels (the components), width N_u,
height T·16·N_φd·N_θd: tile t (1, or 3 for a dispersive paint), element
(i, j) of the matrix in block 4i + j, then N_φd blocks of (θh, θd) rows,
as the M00 LUT's tiles.  Header: ``paintlut:mueller`` (this format's
version), ``paintlut:meta`` (JSON: the type, resolution, quadrature, basis,
parameterization), ``paintlut:key`` and ``paintlut:hash``.
"""

from __future__ import annotations

import concurrent.futures
import json
import pathlib

import numpy as np

from ..lutfiles import angles, baking, table
from ..lutfiles import format as lutfile
from ..models import _validate, facet_reflection
from ..models.rough import DIFFUSE_NODES, SINGLE_NODES
from ..paint.core import COMPONENTS, Paint
from . import basis

#: Version of the Mueller LUT's file format.
MUELLER_FORMAT = 2
#: (N_u, N_θd, N_φd) by default: the M00 LUT's spacing in θh and θd; φd over
#: [0, π] at 3.8° (48 nodes), where the single scattering of a very rough paint
#: changes its polarization fastest (at 32 nodes Mij/M00 of that component
#: was off by up to 0.017 at slope 2.9, 0.008 at 48; more θh or θd nodes did
#: not help).
DEFAULT_RESOLUTION = (64, 32, 48)
PARAMETERIZATION = (
    "rusinkiewicz in the half frame (theta_h=pi/2*u^2, theta_d, phi_d in [0, pi]); "
    "M00 (cos(theta_i) cos(theta_s))^cos_power, the other elements Mij/M00; "
    "below the horizon the point reflection of each ray's values"
)
BASIS = "transported: s = x carried from the nearest pole along the meridian, p = k x s (Duff et al. 2017)"
HALF_PI = np.pi / 2
#: The polar angle that stands for the horizon in ``horizon_terms``.
HORIZON_EDGE = HALF_PI - 1e-5
#: D of the mirror fold: U and V change sign.
MIRROR = np.diag([1.0, 1.0, -1.0, -1.0])


def describe(
    paint: Paint, resolution=DEFAULT_RESOLUTION, single_nodes=SINGLE_NODES, diffuse_nodes=DIFFUSE_NODES
) -> dict:
    """The meta of a Mueller bake: the M00 LUT's (``lut.lutfiles.baking.describe``)
    with this table's parameterization and basis."""
    meta = baking.describe(paint, resolution, single_nodes, diffuse_nodes)
    return {
        **meta,
        "format": MUELLER_FORMAT,
        "parameterization": PARAMETERIZATION,
        "basis": BASIS,
        "cos_power": list(cos_power(paint.slope)),
    }


def cos_power(slope) -> tuple:
    """Per component (facet, single, diffuse), the power p of cos θi·cos θs
    that multiplies M00 in the table (module docstring): the facet's M00 grows
    like 1/(cos θi cos θs) towards the horizon (p = 1); under a smooth
    interface single scattering and the diffuse term fade like the Fresnel
    transmittances, like cos θ (p = -1); under a rough one they stay finite
    (p = 0)."""
    return (1, -1, -1) if slope == 0.0 else (1, 0, 0)


def mueller_lut_path(paint: Paint, directory, **options) -> pathlib.Path:
    """Where ``bake_mueller`` puts (or finds) the Mueller LUT of a paint's type."""
    return pathlib.Path(directory) / f"paintmueller-{lutfile.cache_key(describe(paint, **options))[:24]}.exr"


def _axes(resolution):
    n_u, n_d, n_p = resolution
    u = np.linspace(0.0, 1.0, n_u)
    return HALF_PI * u * u, np.linspace(0.0, HALF_PI, n_d), np.linspace(0.0, np.pi, n_p)


def node_geometry(resolution, clamp=True):
    """Per node (N_φd, N_θd, N_u): model angles (θi, θs, φs), polar angles
    clamped to ``table.HORIZON_CLAMP`` (beyond π/2 below the horizon with
    ``clamp=False``), and the half frame's turn from the models' frame (the
    light's azimuth there minus π)."""
    th, td, pd = _axes(resolution)
    wi, wo = angles.half_frame_rays(th[None, None, :], td[None, :, None], pd[:, None, None])
    light = np.arctan2(wi[..., 1], wi[..., 0])
    view = np.arctan2(wo[..., 1], wo[..., 0])
    ti = np.arccos(np.clip(wi[..., 2], -1.0, 1.0))
    ts = np.arccos(np.clip(wo[..., 2], -1.0, 1.0))
    if clamp:
        ti, ts = np.minimum(ti, table.HORIZON_CLAMP), np.minimum(ts, table.HORIZON_CLAMP)
    ps = np.mod(view - light + 2 * np.pi, 2 * np.pi) - np.pi
    return ti, ts, ps, light - np.pi


def horizon_terms(theta_i, theta_s):
    """What nodes below the horizon hold: each stored value f continued past
    the horizon by its point reflection there, ray by ray,

        f(θ) = 2 f(π/2) - f(π - θ)    (θ > π/2),

    which has f's value and slope at the horizon, so a cell straddling it
    interpolates to second order whatever f does there (fades like cos θ
    under a smooth interface, stays finite under a rough one).  A node with
    both rays below takes the product of the two reflections.  Returns
    (node, weight, θi, θs) of the terms whose weighted sum is each node's
    value (f(π/2) taken at ``HORIZON_EDGE``, where the models still
    scatter)."""
    ti, ts = np.asarray(theta_i, float).ravel(), np.asarray(theta_s, float).ravel()
    nodes = np.arange(ti.size)

    def leg(t, reflected):
        below = t >= HORIZON_EDGE
        if reflected:
            return below, np.full_like(t, -1.0), np.minimum(np.pi - t, HORIZON_EDGE)
        return np.ones_like(below), np.where(below, 2.0, 1.0), np.where(below, HORIZON_EDGE, t)

    parts = []
    for ri in (False, True):
        for rs in (False, True):
            keep_i, w_i, a_i = leg(ti, ri)
            keep_s, w_s, a_s = leg(ts, rs)
            keep = keep_i & keep_s
            parts.append((nodes[keep], (w_i * w_s)[keep], a_i[keep], a_s[keep]))
    return tuple(np.concatenate(column) for column in zip(*parts, strict=True))


def bake_mueller(
    paint: Paint,
    directory,
    *,
    resolution=DEFAULT_RESOLUTION,
    single_nodes=SINGLE_NODES,
    diffuse_nodes=DIFFUSE_NODES,
    force=False,
    chunk=2048,
) -> pathlib.Path:
    """Bake the Mueller matrices of a paint's type into a Mueller LUT file
    in ``directory`` and return its path; a valid cached file is returned
    as it is unless ``force``.  Written atomically (``lut.lutfiles.files``)."""
    if not isinstance(paint, Paint):
        raise ValueError(f"paint must be a lut.Paint, got {type(paint).__name__}")
    meta = describe(paint, resolution, single_nodes, diffuse_nodes)
    key = lutfile.cache_key(meta)
    path = pathlib.Path(directory) / f"paintmueller-{key[:24]}.exr"
    if path.exists() and not force:
        try:
            if load_mueller_lut(path).key == key:  # loading verifies the content hash
                return path
        except lutfile.LUTError:
            pass  # damaged or foreign: bake it again
    return _bake(paint, path, meta, chunk)


def _bake(paint, path, meta, chunk=2048, workers=None):
    """Tabulate every node's values (module docstring; below the horizon
    ``horizon_terms``) in chunks on ``workers`` threads (default
    ``table.default_workers``: numpy releases the interpreter lock inside
    the models' array operations) and write the file."""
    ti, ts, ps, frame = (a.ravel() for a in node_geometry(tuple(meta["resolution"]), clamp=False))
    node, weight, t_i, t_s = horizon_terms(ti, ts)
    p_s, turn = ps[node], frame[node]
    opts = {
        "single_nodes": tuple(meta.get("single_nodes", SINGLE_NODES)),
        "diffuse_nodes": tuple(meta.get("diffuse_nodes", DIFFUSE_NODES)),
    }
    tiles = meta["tiles"]
    power = np.array(meta["cos_power"], dtype=float)
    values = np.empty((node.size, tiles, len(COMPONENTS), 4, 4))

    def run(start):
        sl = slice(start, start + chunk)
        m = paint.components(t_i[sl], t_s[sl], p_s[sl], mueller=True, **opts)  # (n, T, 3, 4, 4), SCATMECH bases
        m = basis.mueller_in_transported_basis(m.reshape(m.shape[0], -1, 4, 4), t_i[sl], t_s[sl], p_s[sl], turn[sl])
        m = m.reshape(-1, tiles, len(COMPONENTS), 4, 4)
        m00 = m[..., :1, :1]
        # Mij/M00 within [-1, 1] (a Mueller matrix's bound), 0 where M00 is 0.
        values[sl] = np.clip(m / np.where(m00 > 0.0, m00, np.inf), -1.0, 1.0)
        values[sl][..., 0, 0] = m00[..., 0, 0] * (np.cos(t_i[sl]) * np.cos(t_s[sl]))[:, None, None] ** power

    workers = table.default_workers() if workers is None else max(1, int(workers))
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers, thread_name_prefix="paint-mueller") as pool:
        for future in [pool.submit(run, start) for start in range(0, node.size, chunk)]:
            future.result()
    out = np.zeros((ti.size, tiles, len(COMPONENTS), 4, 4))
    np.add.at(out, node, weight[:, None, None, None, None] * values)
    n_u, n_d, n_p = meta["resolution"]
    grid = out.reshape(n_p, n_d, n_u, tiles, len(COMPONENTS), 16)
    image = np.ascontiguousarray(np.transpose(grid, (3, 5, 0, 1, 2, 4)).reshape(-1, n_u, len(COMPONENTS)), np.float32)
    if not np.all(np.isfinite(image)):
        raise ValueError(
            "the baked Mueller LUT has values that are not finite: the paint's parameters are outside what a "
            "LUT can hold (for example a slope far below 0.001; use 0 for a smooth surface)"
        )
    meta_json = lutfile.canonical_json(meta)
    attributes = {
        "paintlut:mueller": MUELLER_FORMAT,
        "paintlut:meta": meta_json,
        "paintlut:key": lutfile.cache_key(meta),
    }
    return lutfile.write_exr(path, image, attributes)


class MuellerLUT:
    """A loaded Mueller LUT: ``components(θi, θs, φs)`` the interpolated
    Mueller matrices of the components, ``mueller(θi, θs, φs, paint)`` a
    paint's per RGB channel (both in the transported bases of the models'
    frame, ``lut.polarized.mueller_in_transported_basis``).  ``data`` is
    (T, 16, N_φd, N_θd, N_u, 3) per element and component: M00·(cos θi
    cos θs)^p in element 0 (p = ``meta["cos_power"]`` per component),
    Mij/M00 in the others."""

    def __init__(self, data, meta, path=None, key=""):
        self.data = data
        self.meta = meta
        self.path = path
        self.key = key or lutfile.cache_key(meta)
        tiles = data.shape[0]
        # (N_φd, N_θd, N_u, T·3·16) for one trilinear pass over every element.
        self._flat = np.ascontiguousarray(np.transpose(data, (2, 3, 4, 0, 5, 1)).reshape(data.shape[2:5] + (-1,)))
        self._tiles = tiles

    @property
    def internal_reflectance(self) -> float:
        return float(self.meta["internal_reflectance"])

    def components(self, theta_i, theta_s, phi_s, frame=0.0, closed_facet=None) -> np.ndarray:
        """The components' Mueller matrices [sr⁻¹] at model angles:
        broadcast(angles) + (T, 3, 4, 4); zero at or below the horizon.
        Referred to the transported bases of the models' frame, or of a
        frame turned from it by ``frame`` (radians, broadcast with the
        angles) about the normal, as ``basis.mueller_in_transported_basis``
        refers them: a renderer's shading frame, in which the source lies at
        azimuth π + frame.  ``closed_facet``: the facet component from its
        closed form (``lut.models.facet_reflection``), as the Mitsuba plugin
        evaluates it, rather than from the table; by default wherever the
        type has one n (a dispersive type's facet comes from the table)."""
        if closed_facet is None:
            closed_facet = self._tiles == 1
        if closed_facet and self._tiles != 1:
            raise ValueError("closed_facet needs a paint type with one n (a dispersive type has a tile per channel)")
        ti, ts, ps, frame = np.broadcast_arrays(*_validate.angles(theta_i, theta_s, phi_s), np.asarray(frame, float))
        up = (ti < HALF_PI) & (ts < HALF_PI)
        ti, ts = np.where(up, ti, 0.0), np.where(up, ts, 0.0)  # at or below the horizon: zero, whatever is looked up
        theta_h, theta_d, phi_d, phi_h = angles.half_diff_signed(ti, ts, ps)
        wi = np.stack((-np.sin(ti), np.zeros_like(ti), np.cos(ti)), -1)  # towards the light (azimuth π)
        wo = np.stack((np.sin(ts) * np.cos(ps), np.sin(ts) * np.sin(ps), np.cos(ts)), -1)
        n_p, n_d, n_u = self.data.shape[2:5]
        coords = (
            np.clip(np.abs(phi_d) / np.pi, 0.0, 1.0) * (n_p - 1),
            np.clip(theta_d / HALF_PI, 0.0, 1.0) * (n_d - 1),
            np.sqrt(np.clip(theta_h / HALF_PI, 0.0, 1.0)) * (n_u - 1),
        )
        g = table.trilinear(self._flat, coords).reshape(ti.shape + (self._tiles, len(COMPONENTS), 4, 4))
        g00 = g[..., :1, :1].copy()
        g = g * g00  # M00 (times its cos power) times the normalised elements
        g[..., 0, 0] = g00[..., 0, 0]
        g = np.where((phi_d < 0)[..., None, None, None, None], MIRROR @ g @ MIRROR, g)
        # From the half frame's transported bases to the wanted frame's, per ray.
        psi = []
        for k in (-wi, wo):
            s_half = basis.about_normal(basis.transported_basis(basis.about_normal(k, -phi_h))[0], phi_h)
            s_to = basis.about_normal(basis.transported_basis(basis.about_normal(k, frame))[0], -frame)
            psi.append(basis.turn(k, s_half, np.cross(k, s_half), s_to))
        flat = g.reshape(ti.shape + (-1, 4, 4))
        g = basis.refer(flat, *psi).reshape(g.shape)
        # M00 was stored times (cos θi cos θs)^p, p per component (``cos_power``).
        cos2 = np.where(up, np.cos(ti) * np.cos(ts), 1.0)
        scale = cos2[..., None, None] ** -np.asarray(self.meta["cos_power"], dtype=float)
        out = np.where(up[..., None, None, None, None], g * scale[..., None, None], 0.0)
        kind = self.meta["type"]
        if closed_facet and kind["slope"] > 0.0:
            facet = facet_reflection(ti, ts, ps, n=kind["n"], slope=kind["slope"], distribution=kind["distribution"])
            facet = basis.mueller_in_transported_basis(facet, ti, ts, ps, frame)
            out[..., 0, 0, :, :] = np.where(up[..., None, None], facet, 0.0)
        return out

    def mueller(self, theta_i, theta_s, phi_s, paint: Paint, frame=0.0, closed_facet=None) -> np.ndarray:
        """A paint's (of this type) Mueller matrix per RGB channel,
        broadcast(angles) + (3, 4, 4): Σ_c a_c·M_c (``frame`` and
        ``closed_facet`` as in ``components``)."""
        amps = baking.amplitudes(self.meta, paint, "Mueller LUT")
        comps = self.components(theta_i, theta_s, phi_s, frame, closed_facet)
        comps = np.broadcast_to(comps, comps.shape[:-4] + (3,) + comps.shape[-3:])
        return np.einsum("...hcij,hc->...hij", comps, amps)


def load_mueller_lut(path) -> MuellerLUT:
    """Load and verify a Mueller LUT file; raises lut.LUTError (a
    ValueError) naming the file for a missing, damaged or foreign one."""
    pixels, attrs = lutfile.read_exr_attributes(path, "Mueller LUT file", {"paintlut:mueller": MUELLER_FORMAT})
    try:
        meta = json.loads(attrs.get("paintlut:meta"))
        n_u, n_d, n_p = (int(r) for r in meta["resolution"])
        tiles = int(meta["tiles"])
    except (TypeError, ValueError, KeyError):
        raise lutfile.LUTError(f"{path}: its paintlut:meta is malformed (altered file)") from None
    if attrs.get("paintlut:key") != lutfile.cache_key(meta):
        raise lutfile.LUTError(f"{path}: header key does not match its meta (altered file)")
    if pixels.shape != (tiles * 16 * n_p * n_d, n_u, len(COMPONENTS)):
        raise lutfile.LUTError(f"{path}: image size {pixels.shape} does not match resolution {meta['resolution']}")
    data = pixels.reshape(tiles, 16, n_p, n_d, n_u, len(COMPONENTS))
    return MuellerLUT(data, meta, pathlib.Path(path), attrs["paintlut:key"])


def accuracy(table: MuellerLUT, paint: Paint, steps=17, azimuths=24, closed_facet=None) -> dict:
    """How near a Mueller LUT's matrices of a paint come to the models'
    (``Paint.mueller`` in the transported bases), as the M00 LUT's accuracy
    is measured (docs/lut.md): ``rms`` (4, 4), each element's cos θi-weighted
    RMS error over θi, θs in [0°, 80°] (``steps`` each) and ``azimuths``
    azimuths, relative to M00's RMS, over RGB; ``normalised``: the largest
    error of Mij/M00 at any of those geometries and channels (the state of
    polarization light leaves in); ``poles``: the largest error of an
    element other than M00 relative to M00, and ``poles_m00`` of M00, at
    light or view along the normal (and 1e-6 rad off it) with the other ray
    to 80° all round.  ``closed_facet`` as in ``MuellerLUT.components``."""
    t = np.radians(np.linspace(0.0, 80.0, steps))
    ti, ts, ps = (a.ravel() for a in np.meshgrid(t, t, np.linspace(-np.pi, np.pi, azimuths), indexing="ij"))
    got = table.mueller(ti, ts, ps, paint, closed_facet=closed_facet)
    ref = basis.mueller_in_transported_basis(paint.mueller(ti, ts, ps), ti, ts, ps)
    w = np.cos(ti)[:, None, None, None]
    rms = np.sqrt(np.sum(((got - ref) * w) ** 2, axis=(0, 1)) / np.sum((ref[..., :1, :1] * w) ** 2))
    lit = ref[..., 0, 0] > 0.0
    normalised = float(np.abs(got[lit] / got[lit][:, :1, :1] - ref[lit] / ref[lit][:, :1, :1]).max())
    x, phi = (
        a.ravel()
        for a in np.meshgrid(np.radians(np.linspace(0.0, 80.0, 9)), np.linspace(-np.pi, np.pi, 13), indexing="ij")
    )
    poles, poles_m00 = 0.0, 0.0
    for pole in (0.0, 1e-6):
        for a, b in ((np.full_like(x, pole), x), (x, np.full_like(x, pole))):
            g = table.mueller(a, b, phi, paint, closed_facet=closed_facet)
            r = basis.mueller_in_transported_basis(paint.mueller(a, b, phi), a, b, phi)
            rel = np.abs(g - r) / r[..., :1, :1]
            poles_m00 = max(poles_m00, float(rel[..., 0, 0].max()))
            rel[..., 0, 0] = 0.0
            poles = max(poles, float(rel.max()))
    polarizes = bool(np.abs(ref[..., 1:, :]).max() > 0.01 * np.abs(ref[..., 0, 0]).max())
    return {"rms": rms, "normalised": normalised, "poles": poles, "poles_m00": poles_m00, "polarizes": polarizes}
