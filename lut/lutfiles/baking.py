"""Baking paint types into LUT files, and loading them.

A paint's non-delta BRDF is, per channel, Σ_c a_c · B_c: the angular
components ``lut.paint.COMPONENTS`` (facet reflection, single scattering,
diffuse at ρ = 1) scaled by the amplitudes a_c (the facet weight, the
single-scatter albedo and k(ρ) = ρ(1 - r̄)/(1 - ρ r̄), paper Eq. 27).  Only
the paint's type (n, g, slope, distribution: ``Paint.type_dict``) shapes the
components, so a LUT holds the components of a type and every colour of that
type shares it.

``bake(paint, directory)`` writes ``paintlut-<key>.exr``, the key being the
hash of everything that determines the content (the type, resolution,
quadrature sizes, model and format versions; no colour): baking the same
type twice costs nothing, and two types never share a file.  A cached file
that fails its hash check is baked again.

"""

from __future__ import annotations

import json
import pathlib

import numpy as np

from ..models import _validate
from ..models.rough import DIFFUSE_NODES
from ..paint.core import COMPONENTS, Paint
from . import format as lutfile
from . import table

#: Bumped whenever a model change alters baked values, so old caches miss.
MODEL_VERSION = 2
#: Quadrature of the rough single-scatter term in bakes: coarser than the
#: model's own default (4, 6) because the table's interpolation error
#: dominates; the bake benchmark shows no gain from (4, 6) at 2.8x the time.
BAKE_SINGLE_NODES = (3, 4)


def _resolution(value):
    try:
        res = tuple(int(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(
            f"resolution must be three whole numbers (N_u, N_theta_d, N_phi_d) >= 2, got {value!r}"
        ) from None
    if (
        len(res) != 3
        or any(r < 2 or r > 4096 for r in res)
        or any(float(a) != r for a, r in zip(value, res, strict=True))
    ):
        raise ValueError(
            f"resolution must be three whole numbers (N_u, N_theta_d, N_phi_d) in [2, 4096], got {value!r}"
        )
    return res


def describe(
    paint: Paint, resolution=table.DEFAULT_RESOLUTION, single_nodes=BAKE_SINGLE_NODES, diffuse_nodes=DIFFUSE_NODES
):
    """The meta of a bake: everything that determines the LUT's content, and
    what a renderer needs besides the table: the paint type, the components
    and their tiles (1, or 3 for a dispersive paint: one per RGB channel),
    and the interface's internal reflectance r̄ (which turns a pigment
    colour into the diffuse amplitude).  Quadrature sizes are recorded only
    for rough types."""
    if not isinstance(paint, Paint):
        raise ValueError(f"paint must be a lut.Paint, got {type(paint).__name__}")
    diffuse_nodes = _validate.nodes(diffuse_nodes, "diffuse_nodes")
    meta = {
        "format": lutfile.FORMAT_VERSION,
        "model_version": MODEL_VERSION,
        "parameterization": lutfile.PARAMETERIZATION,
        "resolution": list(_resolution(resolution)),
        "type": paint.type_dict(),
        "components": list(COMPONENTS),
        "tiles": 3 if paint.dispersive else 1,
        "internal_reflectance": paint.internal_reflectance(diffuse_nodes),
    }
    if paint.slope > 0:
        meta["single_nodes"] = list(_validate.nodes(single_nodes, "single_nodes"))
        meta["diffuse_nodes"] = list(diffuse_nodes)
    return meta


def lut_path(paint: Paint, directory, **options) -> pathlib.Path:
    """Where ``bake`` puts (or finds) the LUT of a paint's type."""
    return pathlib.Path(directory) / f"paintlut-{lutfile.cache_key(describe(paint, **options))[:24]}.exr"


def bake(
    paint: Paint,
    directory,
    *,
    resolution=table.DEFAULT_RESOLUTION,
    single_nodes=BAKE_SINGLE_NODES,
    diffuse_nodes=DIFFUSE_NODES,
    force=False,
    progress=None,
) -> pathlib.Path:
    """Bake the angular components of a paint's type (``Paint.components``)
    into a LUT file in ``directory`` and return its path; a valid cached file
    is returned as it is unless ``force``.  ``progress(done, total)`` is
    called as nodes are evaluated (it may raise to stop the bake: nothing is
    written).  See docs/lut.md for the format and its accuracy."""
    meta = describe(paint, resolution, single_nodes, diffuse_nodes)
    path = pathlib.Path(directory) / f"paintlut-{lutfile.cache_key(meta)[:24]}.exr"
    if path.exists() and not force:
        try:
            if lutfile.read(path)[1]["key"] == lutfile.cache_key(meta):  # read verifies the content hash
                return path
        except lutfile.LUTError:
            pass  # damaged or foreign: bake it again
    opts = {"single_nodes": tuple(single_nodes), "diffuse_nodes": tuple(diffuse_nodes)}
    tiles = meta["tiles"]

    def components(ti, ts, ps):
        return paint.components(ti, ts, ps, **opts).reshape(ti.shape + (tiles * len(COMPONENTS),))

    data = table.tabulate(components, tuple(meta["resolution"]), channels=tiles * len(COMPONENTS), progress=progress)
    n_p, n_d, n_u, _ = data.shape
    return lutfile.write(path, np.moveaxis(data.reshape(n_p, n_d, n_u, tiles, 3), 3, 0), meta)


def matches(meta: dict, paint: Paint) -> bool:
    """Whether ``paint`` is of the type a bake's ``meta`` describes."""
    return json.loads(lutfile.canonical_json(paint.type_dict())) == meta["type"]


def amplitudes(meta: dict, paint: Paint, what="LUT") -> np.ndarray:
    """(3 channels, 3 components) amplitudes of a paint of the type a bake's
    ``meta`` describes, with the bake's r̄ (a dispersive paint's from the
    bake's quadrature); ValueError, naming ``what``, for another type."""
    if not matches(meta, paint):
        raise ValueError(f"paint is not of this {what}'s type {meta['type']}")
    if paint.dispersive:
        return paint.amplitudes(tuple(meta.get("diffuse_nodes", DIFFUSE_NODES)))  # JSON gives a list
    return np.stack(paint._weights(float(meta["internal_reflectance"])), axis=1)


class LUT:
    """A loaded LUT of a paint type: ``components(θi, θs, φs)`` gives the
    interpolated angular components, ``evaluate(θi, θs, φs, paint)`` the RGB
    BRDF [sr⁻¹] of a paint of this type (angles as in ``lut.models``),
    ``meta`` its description.  ``data`` is (tiles, N_φd, N_θd, N_u, 3): G =
    f·cos θi·cos θs of each component."""

    def __init__(self, data: np.ndarray, meta: dict, path=None, key: str = ""):
        self.data = data
        self.meta = meta
        self.path = path
        self.key = key or lutfile.cache_key(meta)

    @property
    def internal_reflectance(self) -> float:
        return float(self.meta["internal_reflectance"])

    def matches(self, paint: Paint) -> bool:
        """Whether ``paint`` is of this LUT's type."""
        return matches(self.meta, paint)

    def components(self, theta_i, theta_s, phi_s) -> np.ndarray:
        """Components at model angles: broadcast(angles) + (tiles, 3)."""
        ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s)
        tiles = self.data.shape[0]
        flat = np.moveaxis(self.data, 0, 3).reshape(self.data.shape[1:4] + (tiles * 3,))
        return table.interpolate(flat, ti, ts, ps).reshape(ti.shape + (tiles, 3))

    def amplitudes(self, paint: Paint) -> np.ndarray:
        """(3 channels, 3 components) amplitudes of a paint of this type."""
        return amplitudes(self.meta, paint)

    def evaluate(self, theta_i, theta_s, phi_s, paint: Paint) -> np.ndarray:
        """The RGB BRDF of ``paint`` (of this LUT's type): Σ_c a_c·B_c."""
        comps = self.components(theta_i, theta_s, phi_s)
        amps = self.amplitudes(paint)
        if comps.shape[-2] == 1:
            return comps[..., 0, :] @ amps.T
        return np.einsum("...hc,hc->...h", comps, amps)

    def __repr__(self):
        return f"LUT({str(self.path)!r}, resolution={self.meta['resolution']}, type={self.meta['type']!r})"


def load_lut(path) -> LUT:
    """Load and verify a LUT file.  Raises lut.LUTError (a ValueError) for a
    missing, truncated or altered file, or one of another format version."""
    data, header = lutfile.read(path)
    return LUT(data, header["meta"], pathlib.Path(path), header["key"])
