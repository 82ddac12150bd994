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
import functools
import io

import numpy as np

from .closures import CLOSURE_KINDS, EEVEE_IORS, EEVEE_ROUGHNESS, Closure

#: The grid of the tables: θl and θv in 5° steps to 90°, |φ| in 15° steps.
THETA = np.radians(np.arange(0.0, 90.1, 5.0))
PHI = np.radians(np.arange(0.0, 180.1, 15.0))
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


def _trilinear(table, theta_l, theta_v, phi):
    """The table at (θl, θv, |φ|), trilinear on the grid, held at its edges."""
    idx, frac = [], []
    for a, grid in ((theta_l, THETA), (theta_v, THETA), (np.abs(phi), PHI)):
        x = np.clip((a - grid[0]) / (grid[1] - grid[0]), 0.0, grid.size - 1.0)
        i = np.minimum(np.floor(x).astype(int), grid.size - 2)
        idx.append(i)
        frac.append(x - i)
    out = 0.0
    for corner in range(8):
        bits = [(corner >> b) & 1 for b in range(3)]
        w = 1.0
        for b, f in zip(bits, frac, strict=True):
            w = w * (f if b else 1.0 - f)
        out = out + w * table[idx[0] + bits[0], idx[1] + bits[1], idx[2] + bits[2]]
    return out


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
    return sum((w / total) * _trilinear(data[k], theta_l, theta_v, phi) for k, w in keys.items())


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
