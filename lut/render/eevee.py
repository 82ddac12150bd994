"""The closures as EEVEE renders them (numpy only): measured tables, by
Blender line.

EEVEE does not evaluate closures with Cycles' formulas (``lut.render.closures``).
``scripts/calibrate_eevee.py`` renders each closure kind an EEVEE fit may use
on spheres under a delta Sun and stores, per closure and Blender line, the
ratio of EEVEE's radiance to a smooth analytic reference (``reference``) on
a grid of (θl, θv, |φ|) (``THETA``, ``PHI``) in ``lut/render/eevee_tables.py``.
``evaluate`` is the reference times the interpolated ratio: the same
contract as ``Closure.evaluate`` (contribution per unit irradiance, cos θl
included; light at azimuth π, φ = 0 the mirror direction).

Each kind's reference (what EEVEE was found to approximate: Lambert for its
diffuse closures, GGX for its microfacet lobes), the parameters its tables
are measured at and their calibrated values are the kind's ``eevee`` entry
in the closure registry (``lut.render.closures.CLOSURE_KINDS``): a new kind
is added there alone.

Between the calibrated roughnesses ``ROUGHNESS`` (and IORs ``IORS`` of the
Metallic BSDF) the ratio tables are interpolated linearly, the reference
taking the exact roughness and IOR; outside they are held at the ends."""

from __future__ import annotations

import base64
import collections
import functools
import hashlib
import io
import threading

import numpy as np

from .closures import CLOSURE_KINDS, EEVEE_IORS, EEVEE_ROUGHNESS, Closure

#: The grid of the tables: θl and θv in 5° steps to 90°, |φ| in 15° steps.
THETA = np.radians(np.arange(0.0, 90.1, 5.0))
PHI = np.radians(np.arange(0.0, 180.1, 15.0))
TABLE_SHAPE = (THETA.size, THETA.size, PHI.size)
#: Calibrated roughnesses and Metallic BSDF IORs (``lut.render.closures``).
ROUGHNESS = EEVEE_ROUGHNESS
IORS = EEVEE_IORS
#: Kinds with tables (the closure kinds an EEVEE fit may use): those the
#: closure registry gives an EEVEE response.
KINDS = tuple(kind for kind, spec in CLOSURE_KINDS.items() if spec.eevee is not None)

#: What EEVEE (Blender 5.0, one sample per pixel) sums exactly, measured by
#: scripts/eevee_additivity.py: diffuse closures sharing the surface normal
#: (measured with two Lambert closures: merged into one), plus at most two
#: reflection closures (Glossy, Metallic, any roughness).  Beyond
#: that, or with diffuse closures of different normals (a retro Toon next to
#: a Lambert), EEVEE picks closures at random per pixel, weighted so the mean
#: stays right: the sum is noisy (pixel spread 7-90%) until many samples
#: average it.
EXACT_DIFFUSE_NORMALS = 1
EXACT_REFLECTION_CLOSURES = 2


def _response(closure: Closure):
    response = CLOSURE_KINDS[closure.kind].eevee
    if response is None:
        raise ValueError(f"EEVEE has no calibration of closure kind {closure.kind!r} (calibrated: {', '.join(KINDS)})")
    return response


def table_key(closure: Closure) -> str:
    """The table of a calibrated closure: its kind and the parameters EEVEE's
    rendering of it was measured at (``EeveeResponse.params``)."""
    return "/".join([closure.kind, *(f"{getattr(closure, p):g}" for p in _response(closure).params)])


def reference(closure: Closure, theta_l, theta_v, phi):
    """The analytic model a kind's table corrects (``EeveeResponse.reference``)."""
    theta_l, theta_v, phi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_l, theta_v, phi)))
    return _response(closure).reference(closure, theta_l, theta_v, phi)


# ---------------------------------------------------------------------- tables


def fill(ratio):
    """Fill a table's empty (NaN) cells from their neighbours, outward from
    the measured cells (repeated averaging of the filled 6-neighbours)."""
    out = np.array(ratio, dtype=float)
    if np.all(np.isnan(out)):
        raise ValueError("an empty calibration table")
    while np.isnan(out).any():
        known = ~np.isnan(out)
        total = np.zeros_like(out)
        count = np.zeros_like(out)
        for axis in range(out.ndim):
            for shift in (-1, 1):
                src = np.roll(np.where(known, out, 0.0), shift, axis)
                ok = np.roll(known, shift, axis)
                edge = [slice(None)] * out.ndim
                edge[axis] = 0 if shift == 1 else -1  # no wrap-around
                src[tuple(edge)], ok[tuple(edge)] = 0.0, False
                total += src
                count += ok
        grow = ~known & (count > 0)
        out[grow] = total[grow] / count[grow]
    return out


def encode(tables: dict) -> str:
    """A version's tables ({key: (θl, θv, φ) ratio}) as the text stored in
    ``lut/render/eevee_tables.py``: a compressed .npz (float16), base64."""
    buf = io.BytesIO()
    np.savez_compressed(buf, **{k: np.asarray(v, dtype=np.float16) for k, v in tables.items()})
    return base64.b64encode(buf.getvalue()).decode("ascii")


def decode(text: str) -> dict:
    """``encode``'s inverse: {key: float ratio table}."""
    with np.load(io.BytesIO(base64.b64decode(text))) as data:
        return {k: data[k].astype(float) for k in data.files}


def _version_key(version) -> str:
    if isinstance(version, str):
        parts = version.split(".")
    else:
        parts = list(version)
    try:
        return f"{int(parts[0])}.{int(parts[1])}"
    except (IndexError, ValueError, TypeError):
        raise ValueError(f"version must be (major, minor) or 'major.minor', got {version!r}") from None


def _stored() -> dict:
    from . import eevee_tables

    return eevee_tables.TABLES


def available_versions() -> list:
    """The Blender lines with tables, as (major, minor), oldest first."""
    return sorted(tuple(int(p) for p in v.split(".")) for v in _stored())


@functools.lru_cache(maxsize=8)
def tables(version=(5, 0)) -> dict:
    """The ratio tables of a Blender line ({table key: (θl, θv, φ) array})."""
    key = _version_key(version)
    stored = _stored()
    if key not in stored:
        have = ", ".join(stored) or "none"
        raise ValueError(f"no EEVEE calibration for Blender {key} (calibrated: {have})")
    return decode(stored[key])


#: The last stencils ``_corners`` computed, by the bytes of their
#: geometry: a fit looks up every candidate closure at the same rows.
_STENCILS: collections.OrderedDict = collections.OrderedDict()
_STENCILS_LOCK = threading.Lock()
#: Geometries of more points than this are not remembered (a stencil holds
#: 128 bytes per point).
_STENCIL_POINTS = 200_000


def _corners(theta_l, theta_v, phi):
    """``_stencil``, remembered for the last few geometries (each of a
    fit's candidate closures is looked up at the same rows)."""
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_l, theta_v, phi)))
    digest = hashlib.blake2b(digest_size=16)
    for a in arrays:
        digest.update(a.tobytes())
    key = (arrays[0].shape, digest.digest())
    with _STENCILS_LOCK:
        if key in _STENCILS:
            _STENCILS.move_to_end(key)
            return _STENCILS[key]
    found = _stencil(*arrays)
    if arrays[0].size > _STENCIL_POINTS:  # a calibration's pixels: used once, not worth keeping
        return found
    for a in found:
        a.setflags(write=False)  # shared between callers
    with _STENCILS_LOCK:
        _STENCILS[key] = found
        while len(_STENCILS) > 4:
            _STENCILS.popitem(last=False)
    return found


def _stencil(theta_l, theta_v, phi):
    """The trilinear stencil of (θl, θv, |φ|) on the tables' grid, held at
    its edges: flat cell indices (..., 8) and weights (..., 8), corner c
    taking the upper node along axis b where bit b of c is set."""
    strides = np.array([TABLE_SHAPE[1] * TABLE_SHAPE[2], TABLE_SHAPE[2], 1])
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1  # (8 corners, 3 axes)
    base, lower, upper = 0, [], []
    for axis, (a, grid) in enumerate(((theta_l, THETA), (theta_v, THETA), (np.abs(phi), PHI))):
        x = np.clip((a - grid[0]) / (grid[1] - grid[0]), 0.0, grid.size - 1.0)
        i = np.minimum(np.floor(x).astype(int), grid.size - 2)
        base = base + i * strides[axis]
        upper.append(x - i)
        lower.append(1.0 - upper[-1])
    weights = np.ones(np.shape(base) + (8,))
    for axis in range(3):
        weights *= np.where(bits[:, axis], upper[axis][..., None], lower[axis][..., None])
    return base[..., None] + bits @ strides, weights


def _trilinear(table, theta_l, theta_v, phi):
    """The table at (θl, θv, |φ|), trilinear on the grid, held at its edges."""
    cells, weights = _corners(theta_l, theta_v, phi)
    return np.sum(np.asarray(table).ravel()[cells] * weights, axis=-1)


def fit_table(
    closure: Closure, theta_l, theta_v, phi, radiance, prior, *, weight=None, regularisation=0.05, floor=0.01
):
    """The ratio table of ``closure`` that, interpolated as ``evaluate``
    interpolates it, best reproduces measured ``radiance`` (per unit
    irradiance) at scattered geometries (θl, θv, φ): the weighted least
    squares

        min_T Σ_i u_i (L_i − ref_i · Σ_c w_ic T_c)² / (ref_i + ε)
              + Σ_c λ_c (T_c − prior_c)²,

    u_i the sample's ``weight`` (1 by default: one pixel; a plane's
    geometry, whose pixels all see the same directions, counts as the
    pixels it stands for), w_ic the trilinear weights of ``_corners``, ε = 10⁻³ max ref (so the
    residual counts relative to the lobe, the tails not ignored), λ_c =
    ``regularisation`` × the cell's own diagonal + ``floor`` × the mean
    diagonal (cells the data barely reach stay near ``prior``, e.g. the
    binned ratios Σ L / Σ ref).  Unlike binning, which gives a cell the
    mean ratio of its pixels, weighted toward the side where the lobe is
    brighter, this gives each node the value its interpolation needs: near
    a sharp lobe's mirror at grazing angles the two differ by 10-40%.
    Negative cells (possible far from the lobe) are set to 0."""
    theta_l, theta_v, phi, radiance = (np.ravel(np.asarray(a, dtype=float)) for a in (theta_l, theta_v, phi, radiance))
    ref = reference(closure, theta_l, theta_v, phi)
    scale = 1.0 / np.sqrt(ref + 1e-3 * ref.max())
    if weight is not None:
        scale = scale * np.sqrt(np.broadcast_to(np.asarray(weight, dtype=float), scale.shape))
    cells, weights = _corners(theta_l, theta_v, phi)
    rows = (ref * scale)[:, None] * weights
    size = int(np.prod(TABLE_SHAPE))
    # Normal equations: corners p and q of a stencil are a fixed flat offset
    # apart, so each (p, q) pair fills one band, summed by cell.
    normal = np.zeros((size, size))
    rhs = np.zeros(size)
    for p in range(8):
        rhs += np.bincount(cells[:, p], rows[:, p] * radiance * scale, size)
        for q in range(8):
            offset = int(cells[0, q] - cells[0, p])
            band = np.bincount(cells[:, p], rows[:, p] * rows[:, q], size)
            at = np.nonzero(band)[0]
            normal[at, at + offset] += band[at]
    active = np.nonzero(np.diag(normal) > 0)[0]
    normal = normal[np.ix_(active, active)]
    diag = np.diag(normal).copy()
    lam = regularisation * diag + floor * diag.mean()
    normal[np.diag_indices(active.size)] += lam
    prior = np.asarray(prior, dtype=float)
    out = prior.copy().ravel()
    out[active] = np.linalg.solve(normal, rhs[active] + lam * prior.ravel()[active])
    return np.maximum(out, 0.0).reshape(TABLE_SHAPE)


def _bracket(values, x):
    """Neighbouring calibration values of x and the weight of the upper one."""
    values = np.asarray(values, dtype=float)
    x = float(np.clip(x, values[0], values[-1]))
    j = int(np.clip(np.searchsorted(values, x) - 1, 0, values.size - 2))
    t = (x - values[j]) / (values[j + 1] - values[j])
    return values[j], values[j + 1], t


def ratio(closure: Closure, theta_l, theta_v, phi, version=(5, 0)):
    """EEVEE's radiance over ``reference`` for ``closure``, interpolated."""
    data = tables(version)
    response, kind = _response(closure), closure.kind
    if response.params and not response.grids:  # tables EEVEE renders alike: their mean
        keys = {k: 1.0 for k in data if k.startswith(kind + "/")}
    else:  # multilinear between the calibrated values of each gridded parameter
        keys = {kind: 1.0}
        for param in response.params:
            lo, hi, t = _bracket(response.grids[param], getattr(closure, param))
            grown = {}
            for key, w in keys.items():
                for value, wv in ((lo, 1.0 - t), (hi, t)):
                    name = f"{key}/{value:g}"
                    grown[name] = grown.get(name, 0.0) + w * wv
            keys = grown
    if not keys or any(k not in data for k in keys):
        raise ValueError(f"the Blender {_version_key(version)} tables lack {kind!r}")
    total = sum(keys.values())
    # Trilinear interpolation is linear in the table: blend the tables, then look up once.
    blended = sum((w / total) * np.asarray(data[k], dtype=float) for k, w in keys.items())
    return _trilinear(blended, theta_l, theta_v, phi)


def evaluate(closure: Closure, theta_l, theta_v, phi, version=(5, 0)):
    """EEVEE's contribution of ``closure`` per unit irradiance, cos θl
    included (``Closure.evaluate``'s contract, as EEVEE renders it on
    Blender line ``version``): reference × interpolated ratio.  Raises
    ValueError for a kind not in ``KINDS`` or a version without tables."""
    _response(closure)
    theta_l, theta_v, phi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_l, theta_v, phi)))
    value = reference(closure, theta_l, theta_v, phi) * ratio(closure, theta_l, theta_v, phi, version)
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2)
    return np.where(up, np.maximum(value, 0.0), 0.0)


def calibration_for(blender_version):
    """The calibrated Blender line to use for a running Blender (major,
    minor[, patch]): the same line, else the newest calibrated line of the
    same major version not newer than it; None when there is none (EEVEE of
    Blender 4.x: its fit falls back on Cycles' formulas)."""
    major, minor = int(blender_version[0]), int(blender_version[1])
    same_major = [v for v in available_versions() if v[0] == major and v[1] <= minor]
    return max(same_major) if same_major else None


def is_reflection(closure: Closure) -> bool:
    """Whether EEVEE counts the closure as a reflection closure (its
    microfacet lobes) rather than a diffuse one (``EXACT_REFLECTION_CLOSURES``)."""
    return CLOSURE_KINDS[closure.kind].reflection


def sums_exactly(closures, mirror: bool) -> bool:
    """Whether EEVEE sums these closures exactly at one sample: at most
    ``EXACT_REFLECTION_CLOSURES`` reflection closures (a smooth type's mirror
    takes one) and diffuse closures of one normal (a retro Toon lobe's is the
    view); beyond that ``closure_select`` picks one per bin at random."""
    reflections = sum(is_reflection(c) for c in closures) + bool(mirror)
    normals = {c.kind == "retro_toon" for c in closures if not is_reflection(c)}
    return reflections <= EXACT_REFLECTION_CLOSURES and len(normals) <= 1


#: Render samples of an EEVEE viewport (Blender's default,
#: ``scene.eevee.taa_samples``): the noise a converged fit may spend is
#: judged there.
VIEWPORT_SAMPLES = 16
#: ``samples_needed``: a render has converged where its per-pixel spread
#: is below the fit's own error at that colour (more samples no longer
#: bring its pixels nearer the model), and below this at least.
NOISE_FLOOR = 0.02
#: How the spread falls with samples: as N^-CONVERGENCE.  EEVEE's sample
#: sequence is stratified, faster than independent samples' N^-0.5:
#: measured on a flat plane (``scripts/eevee_converged.py --render``) the
#: spread fell 5-9 fold from 1 to 16 samples and 18-20 fold to 64.
CONVERGENCE = 0.7


def _colours(weights, cos_view, amplitudes, theta_v, columns=False):
    """Σ_c a_c·w_kc: each closure's colour (K, N, 3) at views θv (N,) as
    the node group reads its weights: those of ``texture_weights`` for
    weights fitted at ``cos_view``, or with ``columns`` the weights
    texture's own columns at ``cos_view`` (a ``Fit``'s), read at the
    column nearest to each view."""
    from .fitting import closure_colours, read_weights

    return closure_colours(read_weights(weights, cos_view, np.cos(theta_v), columns), amplitudes)


def _selection(closures, colours, facet, mirror_n, values):
    """Per closure the contribution C_k (K', N, 3) EEVEE's mean renders and
    the weight s_k (K', N) ``closure_select`` picks it by (the closure's
    weight times the mean of its colour), a smooth type's mirror last
    (``mirror_n``, its IOR, or None: no contribution off its delta, but a
    share of its bin).  A grey lobe is a Mix Shader factor (clamped to
    [0, 1]) times a lobe whose colour is taken as its Fresnel factor at
    normal incidence."""
    contributions, weights = [], []
    for k, closure in enumerate(closures):
        if closure.grey:
            factor = np.clip(colours[k].mean(axis=-1), 0.0, 1.0)
            contributions.append((factor * values[k])[:, None] * np.ones(3))
            weights.append(factor * ((closure.ior - 1.0) / (closure.ior + 1.0)) ** 2)
        else:
            contributions.append(colours[k] * values[k][:, None])
            weights.append(np.abs(colours[k]).mean(axis=-1))
    n_points = values.shape[1]
    if mirror_n is not None:
        contributions.append(np.zeros((n_points, 3)))
        weights.append(np.full(n_points, facet * ((mirror_n - 1.0) / (mirror_n + 1.0)) ** 2))
    return np.array(contributions).reshape(-1, n_points, 3), np.array(weights).reshape(-1, n_points)


#: Bits of each channel of a closure colour in EEVEE's G-buffer
#: (``gbuffer_closure_color_pack`` in EEVEE's GLSL, Blender 4.2-5.2: a
#: 10_10_10_2 unsigned normalised texel, the 2 bits a shared exponent).
COLOUR_BITS = 10

#: How a closure colour is rounded to the G-buffer's steps
#: (``COLOUR_ROUNDINGS``).  OpenGL leaves it to the implementation; Mesa's
#: software OpenGL, where this project's renders are checked, truncates:
#: white closures scaled to colours 0.005-0.1 render 0.977-0.997 times the
#: weight-1 render, floor(c·1023)/(c·1023) to three digits (docs/eevee.md,
#: Dark colours).  A GPU that rounds to the nearest step loses nothing on
#: average.
COLOUR_ROUNDING = "floor"
COLOUR_ROUNDINGS = {"floor": np.floor, "nearest": np.rint, "none": None}


def validate_rounding(rounding: str) -> str:
    """``rounding`` if it is one of ``COLOUR_ROUNDINGS``, else ValueError."""
    if rounding not in COLOUR_ROUNDINGS:
        raise ValueError(f"colour rounding {rounding!r} is not one of {sorted(COLOUR_ROUNDINGS)}")
    return rounding


def stored_colour(colour, rounding: str = COLOUR_ROUNDING):
    """A closure colour (..., 3) as EEVEE's G-buffer keeps it: divided by
    2^e, e = 0 for a largest channel up to 1, 1 up to 2, 2 up to 4, else 3
    (clamped at 8), each channel then on steps of 1/(2^COLOUR_BITS - 1)
    (``gbuffer_closure_color_pack``), rounded as ``rounding`` says.
    Negative channels (not in an EEVEE fit) are kept at 0."""
    step = COLOUR_ROUNDINGS[validate_rounding(rounding)]
    c = np.maximum(np.asarray(colour, dtype=float), 0.0)
    if step is None:
        return c
    top = c.max(axis=-1, keepdims=True)
    scale = np.where(top > 4.0, 8.0, np.where(top > 2.0, 4.0, np.where(top > 1.0, 2.0, 1.0)))
    levels = 2**COLOUR_BITS - 1
    # A hair above each exact step, so a colour the node group computes as
    # k/1023 in floats does not fall to the step below it.
    return step(np.clip(c / scale, 0.0, 1.0) * levels * (1.0 + 1e-7)) / levels * scale


def mean_radiance(closures, colours, values, mirror_n, facet, rounding: str = COLOUR_ROUNDING):
    """The RGB radiance (N, 3) of EEVEE's render averaged over samples, with
    each closure colour as the G-buffer keeps it (``stored_colour``).
    ``colours`` (K, N, 3), ``values`` (K, N): the closures' colours and
    responses; ``mirror_n``: a smooth type's IOR (its mirror shares a bin)
    or None; ``facet``: the mean facet amplitude (the mirror's weight).

    Where EEVEE sums the closures exactly, the diffuse ones of a bin are one
    layer (their colours added, then stored) and each reflection closure is
    stored alone.  Otherwise ``closure_select`` keeps closure k of a bin with
    probability p_k and stores its colour divided by p_k, so the mean is
    Σ p_k·stored(C_k/p_k)·value_k.  A grey lobe's colour is its Mix Shader
    factor (``_selection``)."""
    closures = list(closures)
    values = np.asarray(values, dtype=float)
    colours = np.asarray(colours, dtype=float)
    n_points = values.shape[1]
    mirror = mirror_n is not None
    grey = [c.grey for c in closures]
    # What the G-buffer stores of each closure: a grey lobe's factor (one
    # value for every channel, its Mix Shader's), else its colour.
    tints = np.array(
        [
            np.clip(colours[k].mean(axis=-1), 0.0, 1.0)[:, None] * np.ones(3) if grey[k] else colours[k]
            for k in range(len(closures))
        ]
    ).reshape(len(closures), n_points, 3)

    def kept(k, tint, p):
        """Closure k's colour once its tint (kept with probability p) is stored."""
        return (
            np.divide(p * stored_colour(tint / p, rounding), tint, out=np.ones_like(tint), where=tint > 0) * colours[k]
        )

    out = np.zeros((n_points, 3))
    if sums_exactly(closures, mirror):
        diffuse = [k for k, c in enumerate(closures) if not is_reflection(c)]
        if diffuse:  # one layer: the colours added, then stored
            layer = tints[diffuse].sum(axis=0)
            ratio = np.divide(stored_colour(layer, rounding), layer, out=np.ones_like(layer), where=layer > 0)
            out += ratio * np.einsum("kn,knh->nh", values[diffuse], colours[diffuse])
        for k in range(len(closures)):
            if is_reflection(closures[k]):
                out += kept(k, tints[k], np.ones((n_points, 1))) * values[k][:, None]
        return out
    _, select = _selection(closures, colours, facet, mirror_n, values)
    which = np.array(bins(closures, mirror))
    for k in range(len(closures)):
        total = select[which == which[k]].sum(axis=0)
        p = np.where(total > 0, select[k] / np.where(total > 0, total, 1.0), 0.0)[:, None]
        out += np.where(p > 0, kept(k, tints[k], np.where(p > 0, p, 1.0)), 0.0) * values[k][:, None]
    return out


def bins(closures, mirror: bool) -> list:
    """The closure bin each closure (and a smooth type's mirror, last) falls
    in: 0 the diffuse one; reflection closures alternate between bins 2
    and 1 in the order the node group sums them (EEVEE's
    ``CHOOSE_MIN_WEIGHT_CLOSURE_BIN``)."""
    out, nth = [], 0
    for reflection in [is_reflection(c) for c in closures] + ([True] if mirror else []):
        if reflection:
            out.append(2 - nth % 2)
            nth += 1
        else:
            out.append(0)
    return out


def spread_of(
    closures, weights, cos_view, mirror, n, amplitudes, points, version, samples=1, values=None, columns=False
):
    """``spread`` of closures with weights (K, C, M, T) at view cosines
    ``cos_view`` (with ``columns``, the weights texture's own columns, as a
    ``Fit`` holds them; else weights fitted there, which the texture
    resamples); ``n``: the type's IOR (its mirror's), ``version``: the
    calibrated Blender line (None: Cycles' formulas); ``values``: the
    closures' responses at ``points`` (K, N), when computed already."""
    if sums_exactly(closures, mirror):
        return 0.0
    theta_l, theta_v, phi = (np.asarray(a, dtype=float).ravel() for a in points)
    if values is None:
        values = np.array([evaluate_closure(c, theta_l, theta_v, phi, version) for c in closures])
    values = np.asarray(values, dtype=float).reshape(len(closures), theta_l.size)
    colours = _colours(weights, cos_view, amplitudes, theta_v, columns)
    facet = float(np.mean(np.asarray(amplitudes, dtype=float)[:, 0]))
    contributions, select = _selection(closures, colours, facet, n if mirror else None, values)
    which = np.array(bins(closures, mirror))
    variance = np.zeros((theta_l.size, 3))
    for b in np.unique(which):
        c, s = contributions[which == b], select[which == b]
        total = s.sum(axis=0)
        p = s / np.where(total > 0, total, 1.0)
        inverse = np.where(p > 0, 1.0 / np.where(p > 0, p, 1.0), 0.0)
        variance += np.maximum(np.sum(c**2 * inverse[..., None], axis=0) - c.sum(axis=0) ** 2, 0.0)
    den = float(np.sum(contributions.sum(axis=0) ** 2))
    if den <= 0:
        return 0.0
    return float(np.sqrt(variance.sum() / den) / max(int(samples), 1) ** CONVERGENCE)


def spread(fit, amplitudes, samples=1, points=None):
    """The per-pixel spread of EEVEE's render of a fit at a colour
    (``amplitudes``, ``Paint.amplitudes``) at ``samples`` samples:
    sqrt(Σ variance / Σ L²) over RGB and the fidelity measure's geometries
    (``points``: (θl, θv, φ) arrays; default the measure's own), formed as
    the measure itself is.

    Per pixel and sample EEVEE keeps one closure per bin (``bins``),
    closure k with probability p_k = s_k/Σs (``_selection``) and scaled by
    1/p_k, so a bin's estimate X has mean Σ C_k and variance
    Σ C_k²/p_k - (Σ C_k)²; the bins' variances are added (their shared
    random number ignored), and fall with samples as N^-CONVERGENCE.  0
    for a fit EEVEE sums exactly.  Checked against renders of a flat plane
    at one sample: 168% predicted where 169% was measured, 5-12% where
    3-9% were."""
    if fit.target != "EEVEE":
        return 0.0
    from . import measure

    points = measure.points(fit.mirror) if points is None else points
    version = tuple(fit.calibration) if fit.calibration else None
    return spread_of(
        fit.closures, fit.weights, fit.cos_view, fit.mirror, fit.n, amplitudes, points, version, samples, columns=True
    )


def evaluate_closure(closure, theta_l, theta_v, phi, version):
    """EEVEE's response of a closure where calibrated (``evaluate``), else
    Cycles' formula (an uncalibrated Blender line)."""
    if version is not None:
        return evaluate(closure, theta_l, theta_v, phi, version)
    return closure.evaluate(theta_l, theta_v, phi)


def samples_needed(fit, amplitudes, bound=None, most=4096) -> int:
    """The fewest EEVEE samples (a power of two) at which a fit's per-pixel
    spread (``spread``) at a colour is within ``bound`` (default: the fit's
    error at that colour, ``NOISE_FLOOR`` at least): 1 for a fit EEVEE sums
    exactly; ``most`` at most."""
    if bound is None:
        bound = max(fit.error(amplitudes), NOISE_FLOOR)
    return samples_for(spread(fit, amplitudes), bound, most)


def samples_for(one: float, bound: float, most=4096) -> int:
    """The fewest samples (a power of two, ``most`` at most) at which a
    spread of ``one`` at one sample falls within ``bound``."""
    samples = 1
    while one / samples**CONVERGENCE > bound and samples < most:
        samples *= 2
    return samples


def component_colours(components: int) -> list:
    """Amplitudes (3 channels, C) of each component alone at unit colour:
    the colours a type's noise is judged at (a black paint is all facet)."""
    return [np.repeat(np.eye(components)[c][None], 3, axis=0) for c in range(components)]


def type_spread(fit) -> float:
    """The spread at one sample (``spread``) of a type's noisiest colour:
    the largest over the colours of one component alone
    (``component_colours``)."""
    if fit.target != "EEVEE" or fit.sums_exactly:
        return 0.0
    return max(spread(fit, amps) for amps in component_colours(fit.weights.shape[1]))
