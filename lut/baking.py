"""Baking paints into LUT files, and loading them.

``bake(paint, directory)`` writes ``paintlut-<key>.exr``, the key being the
hash of everything that determines the content (paint parameters, working
space, resolution, quadrature sizes, model and format versions): baking the
same paint twice costs nothing, and two paints never share a file.  A cached
file that fails its hash check is baked again."""

from __future__ import annotations

import pathlib

import numpy as np

from . import lutfile, table
from .models import _validate
from .models.rough import DIFFUSE_NODES
from .paint import Paint

#: Bumped whenever a model change alters baked values, so old caches miss.
MODEL_VERSION = 1
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
    """The meta of a bake: everything that determines the LUT's content.
    Quadrature sizes are recorded only where the paint uses them."""
    if not isinstance(paint, Paint):
        raise ValueError(f"paint must be a lut.Paint, got {type(paint).__name__}")
    paint_dict = paint.to_dict()
    paint_dict.pop("name")
    meta = {
        "format": lutfile.FORMAT_VERSION,
        "model_version": MODEL_VERSION,
        "parameterization": lutfile.PARAMETERIZATION,
        "resolution": list(_resolution(resolution)),
        "space": paint.space,
        "paint": paint_dict,
    }
    if paint.slope > 0 and paint.has_single:
        meta["single_nodes"] = list(_validate.nodes(single_nodes, "single_nodes"))
    if paint.slope > 0 and paint.has_diffuse:
        meta["diffuse_nodes"] = list(_validate.nodes(diffuse_nodes, "diffuse_nodes"))
    return meta


def lut_path(paint: Paint, directory, **options) -> pathlib.Path:
    """Where ``bake`` puts (or finds) the LUT of a paint."""
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
    """Bake a paint's polarization-averaged RGB BRDF into a LUT file in
    ``directory`` and return its path; a valid cached file is returned as it
    is unless ``force``.  ``progress(done, total)`` is called as nodes are
    evaluated.  See docs/lut.md for the format and its accuracy."""
    meta = describe(paint, resolution, single_nodes, diffuse_nodes)
    path = pathlib.Path(directory) / f"paintlut-{lutfile.cache_key(meta)[:24]}.exr"
    if path.exists() and not force:
        try:
            if lutfile.read(path)[1]["key"] == lutfile.cache_key(meta):  # read verifies the content hash
                return path
        except lutfile.LUTError:
            pass  # damaged or foreign: bake it again
    opts = {"single_nodes": tuple(single_nodes), "diffuse_nodes": tuple(diffuse_nodes)}

    def brdf(ti, ts, ps):
        return paint.brdf(ti, ts, ps, **opts)

    data = table.tabulate(brdf, tuple(meta["resolution"]), progress=progress)
    return lutfile.write(path, data, meta)


class LUT:
    """A loaded LUT: ``evaluate(θi, θs, φs)`` gives the interpolated RGB BRDF
    [sr⁻¹] (angles as in ``lut.models``), ``meta`` its description and
    ``paint`` the paint it was baked from."""

    def __init__(self, data: np.ndarray, meta: dict, path=None):
        self.data = data
        self.meta = meta
        self.path = path

    @property
    def paint(self) -> Paint:
        return Paint.from_dict(self.meta["paint"])

    def evaluate(self, theta_i, theta_s, phi_s) -> np.ndarray:
        ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s)
        return table.interpolate(self.data, ti, ts, ps)

    def __repr__(self):
        return f"LUT({str(self.path)!r}, resolution={self.meta['resolution']}, space={self.meta['space']!r})"


def load_lut(path) -> LUT:
    """Load and verify a LUT file.  Raises lut.LUTError (a ValueError) for a
    missing, truncated or altered file, or one of another format version."""
    data, header = lutfile.read(path)
    return LUT(data, header["meta"], pathlib.Path(path))
