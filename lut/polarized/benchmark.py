"""Measurements of the Mitsuba plugin (``scripts/benchmark_mitsuba.py`` is
the command): the Mueller LUT's bake time and size, the render time of a
scene with ``germer_paint`` against the same scene with Mitsuba's
``pplastic`` given the same paint (the same variant), and the two side by
side with the models on the plane oracle.  Needs mitsuba."""

from __future__ import annotations

import pathlib
import tempfile
import time

import numpy as np

from ..paint.core import Paint
from . import mueller_lut, scenes


def bake_cost(paint: Paint) -> dict:
    """Seconds and megabytes of a fresh Mueller LUT bake of the paint's type
    (default resolution)."""
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        path = mueller_lut.bake_mueller(paint, tmp, force=True)
        seconds = time.perf_counter() - start
        size = pathlib.Path(path).stat().st_size
    return {"seconds": seconds, "megabytes": size / 1e6}


def render_ratio(paint: Paint, *, size=64, spp=8, cache=None, variant=None) -> dict:
    """Render seconds of the sphere scene (``scenes.sphere_scene``) with
    germer_paint and with pplastic, and their ratio; each scene is rendered
    twice and the second timed, so a JIT variant's kernels are compiled (and
    the Mueller LUT baked) before the clock runs."""
    from . import pictures

    for _ in range(2):
        rendered = pictures.render(paint, size=size, spp=spp, cache=cache, variant=variant)
    seconds = rendered["seconds"]
    return {**seconds, "ratio": seconds["germer_paint"] / seconds["pplastic"], "variant": rendered["variant"]}


def side_by_side(paint: Paint, geometries, *, cache=None) -> list[dict]:
    """Per geometry (θl, φl, θv, φv in degrees, the plane oracle's, unpolarized
    sun): S0 and the degree of linear polarization (green channel) of the
    models, germer_paint and pplastic.  The renderer's white (its Lambertian
    in the same set-up) is divided out of the renders."""
    import mitsuba as mi

    germer, pplastic = mi.load_dict(scenes.germer_dict(paint, cache)), mi.load_dict(scenes.pplastic_dict(paint))
    white = mi.load_dict({"type": "diffuse", "reflectance": {"type": "rgb", "value": 1.0}})
    rows = []
    for tl, pl, tv, pv in geometries:
        light = scenes.direction(*np.radians([tl, pl]))
        view = scenes.direction(*np.radians([tv, pv]))
        scale = scenes.plane_oracle(white, light, view)[0] / (light[2] / np.pi)
        row = {"geometry": (tl, pl, tv, pv)}
        for name, stokes in (
            ("model", scenes.model_stokes(paint, *np.radians([tl, pl, tv, pv]))),
            ("germer_paint", scenes.plane_oracle(germer, light, view) / scale),
            ("pplastic", scenes.plane_oracle(pplastic, light, view) / scale),
        ):
            row[name] = {"S0": float(stokes[0]), "DoLP": float(np.hypot(stokes[1], stokes[2]) / stokes[0])}
        rows.append(row)
    return rows
