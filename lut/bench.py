"""Measurements behind scripts/benchmark_models.py: model throughput, and run
time against error for the rough models (numpy only)."""

from __future__ import annotations

import time

import numpy as np

from . import models
from .models import reference
from .render import measure

CLOSED_FORM = {
    "facet_reflection": (models.facet_reflection, {"n": 1.5, "slope": 0.3}),
    "facet_transmission": (models.facet_transmission, {"n": 1.5, "slope": 0.3}),
    "smooth_diffuse": (models.smooth_diffuse, {"n": 1.5, "rho": 0.93}),
    "smooth_single": (models.smooth_single, {"n": 1.5, "g": 0.3}),
}

#: The benchmark paints for the rough models: satin and matte (the paper's CARC).
ROUGH_PAINTS = {
    "satin (gaussian, slope 0.25)": {"n": 1.5, "slope": 0.25, "distribution": "gaussian"},
    "matte (exponential, slope 2)": {"n": 1.5, "slope": 2.0, "distribution": "exponential"},
}


def best_time(repeat, fn, *args, **kwargs):
    """Shortest wall time of ``repeat`` calls of fn(*args, **kwargs), and the
    last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn(*args, **kwargs)
        best = min(best, time.perf_counter() - start)
    return best, out


MAX_THETA = np.radians(85.0)


def random_angles(count, seed=0, max_theta=MAX_THETA):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, max_theta, count), rng.uniform(0, max_theta, count), rng.uniform(-np.pi, np.pi, count)


def throughput(count=100_000, grid=False):
    """Seconds per evaluation of each closed-form model on ``count`` random
    angles, or with ``grid`` on a (θi, θs, φs) grid of about that size passed
    as broadcastable axes (how LUTs are baked): full Mueller and M00 alone."""
    if grid:
        side = round((count / 2) ** (1 / 3))
        ti = np.linspace(0.0, MAX_THETA, side)[:, None, None]
        ts = np.linspace(0.0, MAX_THETA, side)[None, :, None]
        ps = np.linspace(0.0, np.pi, 2 * side)[None, None, :]
        count = side * side * 2 * side
    else:
        ti, ts, ps = random_angles(count)
    rows = {}
    for name, (fn, kw) in CLOSED_FORM.items():
        t_full, _ = best_time(3, fn, ti, ts, ps, **kw)
        t_m00, _ = best_time(3, fn, ti, ts, ps, mueller=False, **kw)
        rows[name] = {"full": t_full / count, "m00": t_m00 / count}
    return rows


def table_angles(shape=(64, 64, 32)):
    """The benchmark's (θi, θs, φs) table: midpoints in θ ∈ [0, π/2), φ ∈ [0, π]."""
    ti = (np.arange(shape[0]) + 0.5) / shape[0] * np.pi / 2
    ts = (np.arange(shape[1]) + 0.5) / shape[1] * np.pi / 2
    ps = np.linspace(0.0, np.pi, shape[2])
    return np.meshgrid(ti, ts, ps, indexing="ij")


def relative_rms(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2)))


def rough_time_vs_error(
    shape=(64, 64, 32),
    single_nodes=((2, 4), (3, 4), (4, 6), (6, 8)),
    diffuse_nodes=((4, 8), (8, 8), (16, 16)),
    mc_pairs=(100, 1000, 10000),
    sample=1500,
    seed=1,
):
    """Time to fill the (θi, θs, φs) table with M00 of each rough model against
    its relative RMS error, measured on a random subsample of the table
    against a converged quadrature; and the paper's random-pairs method,
    timed on the subsample and scaled to the table."""
    ti, ts, ps = table_angles(shape)
    size = ti.size
    pick = np.random.default_rng(seed).choice(size, sample, replace=False)
    si, ss, sp = ti.ravel()[pick], ts.ravel()[pick], ps.ravel()[pick]
    report = {}
    for paint, kw in ROUGH_PAINTS.items():
        rows = []
        ref = models.rough_single(si, ss, sp, g=0.3, mueller=False, nodes=(12, 16), **kw)
        for nodes in single_nodes:
            t, table = best_time(1, models.rough_single, ti, ts, ps, g=0.3, mueller=False, nodes=nodes, **kw)
            err = relative_rms(table.ravel()[pick], ref)
            rows.append({"model": "rough_single", "method": f"quadrature {nodes}", "seconds": t, "rms_error": err})
        for pairs in mc_pairs:
            t, got = best_time(1, reference.rough_single_random, si, ss, sp, g=0.3, pairs=pairs, seed=seed, **kw)
            rows.append(
                {
                    "model": "rough_single",
                    "method": f"random pairs {pairs}",
                    "seconds": t * size / sample,
                    "rms_error": relative_rms(got, ref),
                }
            )
        ref_d = models.rough_diffuse(si, ss, sp, rho=0.8, mueller=False, nodes=(48, 48), **kw)
        for nodes in diffuse_nodes:
            models.rough_internal_reflectance.cache_clear()
            t, table = best_time(1, models.rough_diffuse, ti, ts, ps, rho=0.8, mueller=False, nodes=nodes, **kw)
            rows.append(
                {
                    "model": "rough_diffuse",
                    "method": f"quadrature {nodes}",
                    "seconds": t,
                    "rms_error": relative_rms(table.ravel()[pick], ref_d),
                }
            )
        report[paint] = rows
    return report


def speedup_at_equal_error(rows, target_method):
    """How much faster the quadrature ``target_method`` is than the random
    pairs method at the same error, using MC error ∝ 1/sqrt(pairs) and time ∝
    pairs fitted to the measured random-pairs rows."""
    target = next(r for r in rows if r["method"] == target_method)
    mc = [r for r in rows if r["method"].startswith("random pairs")]
    pairs = np.array([float(r["method"].split()[-1]) for r in mc])
    err = np.array([r["rms_error"] for r in mc])
    secs = np.array([r["seconds"] for r in mc])
    c_err = np.exp(np.mean(np.log(err * np.sqrt(pairs))))  # err = c / sqrt(N)
    c_time = secs[-1] / pairs[-1]  # time per pair, from the largest run
    needed = (c_err / target["rms_error"]) ** 2
    return needed * c_time / target["seconds"], needed


#: Bake settings the bake benchmark sweeps: (resolution, single-scatter nodes).
BAKE_SETTINGS = [
    ((32, 16, 8), (3, 4)),
    ((48, 24, 12), (3, 4)),
    ((64, 32, 16), (3, 4)),
    ((64, 32, 16), (4, 6)),
    ((96, 48, 24), (4, 6)),
]


def validation_angles(count=2000, seed=4):
    """Random directions with θi, θs <= 80° and any azimuth."""
    rng = np.random.default_rng(seed)
    limit = np.radians(80.0)
    return rng.uniform(0, limit, count), rng.uniform(0, limit, count), rng.uniform(-np.pi, np.pi, count)


def cos_weighted_error(got, ref, theta_i):
    """sqrt(Σ((lut - model)·cos θi)² / Σ(model·cos θi)²) over all channels."""
    w = np.cos(theta_i)[..., None]
    return float(np.sqrt(np.sum(((got - ref) * w) ** 2) / np.sum((ref * w) ** 2)))


def bake_time_vs_error(paints, settings=BAKE_SETTINGS, directory=None, count=2000):
    """For each paint and setting: bake time (forced, no cache) and the LUT's
    cos-weighted relative RMS error against the model with converged
    quadrature, on ``count`` random directions.  Returns {name: [rows]}."""
    import tempfile

    from .lutfiles import baking

    ti, ts, ps = validation_angles(count)
    report = {}
    with tempfile.TemporaryDirectory() as tmp:
        directory = directory or tmp
        for name, paint in paints.items():
            ref = paint.brdf(ti, ts, ps, single_nodes=(12, 16), diffuse_nodes=(32, 32))
            rows = []
            for resolution, single_nodes in settings:
                start = time.perf_counter()
                path = baking.bake(paint, directory, resolution=resolution, single_nodes=single_nodes, force=True)
                seconds = time.perf_counter() - start
                err = cos_weighted_error(baking.load_lut(path).evaluate(ti, ts, ps, paint), ref, ti)
                rows.append({"resolution": resolution, "single_nodes": single_nodes, "seconds": seconds, "error": err})
            report[name] = rows
    return report


def random_paints(count=24, seed=2026):
    """A randomised acceptance set spanning the panel's ranges (fixed seed):
    n 1.3-2.0; ρ per channel log-uniform over 0.01-0.9 (dark and light);
    single scattering 0-0.3 per channel, in a third of the paints dominant
    over a dark pigment; g uniform over -0.7..0.8 (both signs); a quarter
    smooth, the rest slopes log-uniform over 0.05-3 with either distribution;
    surface reflection 0.5-1.  Returns [(label, lut.Paint)]."""
    from .paint.core import Paint

    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        rho = np.exp(rng.uniform(np.log(0.01), np.log(0.9), 3))
        single = rng.uniform(0.0, 0.3, 3)
        if i % 3 == 2:  # single scattering dominant over a dark pigment
            rho = np.exp(rng.uniform(np.log(0.01), np.log(0.06), 3))
        smooth = i % 4 == 0
        slope = 0.0 if smooth else float(np.exp(rng.uniform(np.log(0.05), np.log(3.0))))
        distribution = "gaussian" if rng.random() < 0.5 else "exponential"
        paint = Paint(
            n=round(float(rng.uniform(1.3, 2.0)), 3),
            rho=tuple(round(float(v), 4) for v in rho),
            single=tuple(round(float(v), 4) for v in single),
            g=round(float(rng.uniform(-0.7, 0.8)), 3),
            slope=round(slope, 4),
            distribution=distribution,
            facet=round(float(rng.uniform(0.5, 1.0)), 3),
        )
        kind = "smooth" if smooth else f"{distribution[:3]} {paint.slope:g}"
        out.append((f"#{i} {kind} g {paint.g:+.2f}", paint))
    return out


def dark_paints(count=24, seed=2027):
    """A randomised set of dark rough paints, dominated by the facet term
    (fixed seed): ρ per channel log-uniform over 0.01-0.05, single
    scattering 0-0.03 per channel, g uniform over -0.7..0.8, n 1.3-2.0,
    slopes log-uniform over 0.05-3 with either distribution (alternating),
    surface reflection 0.5-1.  The corner of the panel where the render path
    shows the facet term almost alone.  Returns [(label, lut.Paint)]."""
    from .paint.core import Paint

    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        distribution = "gaussian" if i % 2 == 0 else "exponential"
        paint = Paint(
            n=round(float(rng.uniform(1.3, 2.0)), 3),
            rho=tuple(round(float(v), 4) for v in np.exp(rng.uniform(np.log(0.01), np.log(0.05), 3))),
            single=tuple(round(float(v), 4) for v in rng.uniform(0.0, 0.03, 3)),
            g=round(float(rng.uniform(-0.7, 0.8)), 3),
            slope=round(float(np.exp(rng.uniform(np.log(0.05), np.log(3.0)))), 4),
            distribution=distribution,
            facet=round(float(rng.uniform(0.5, 1.0)), 3),
        )
        out.append((f"dark #{i} {distribution[:3]} {paint.slope:g} g {paint.g:+.2f}", paint))
    return out


def render_bake_times(paints, directory, repeat=1, eevee_calibration=(5, 0)):
    """Seconds of a cold ``lut.render.bake.bake_for_render`` (the paint type's LUT
    and every engine's fit, as the add-on's Bake does) per paint, split into
    the LUT and the fits, and of a cached one (another colour of the type):
    [(label, lut seconds, fits seconds, total, cached seconds)], best of
    ``repeat``."""
    import tempfile

    from .lutfiles import baking
    from .render import bake as render_bake

    rows = []
    for label, paint in paints:
        best = None
        for _ in range(repeat):
            with tempfile.TemporaryDirectory(dir=directory) as tmp:
                start = time.perf_counter()
                baking.bake(paint, tmp)
                lut_done = time.perf_counter()
                render_bake.bake_for_render(
                    paint, tmp, eevee_calibration=eevee_calibration, osl=True
                )  # the LUT is cached: fits only (Cycles' OSL variant too, as the add-on bakes)
                end = time.perf_counter()
                render_bake.bake_for_render(paint, tmp, eevee_calibration=eevee_calibration, osl=True)  # all cached
                cached = time.perf_counter() - end
                row = (lut_done - start, end - lut_done, end - start, cached)
                if best is None or row[2] < best[2]:
                    best = row
        rows.append((label, *best))
    return rows


#: Samples nearer the mirror direction than this are left out of
#: ``binned_error`` for a smooth paint (the fidelity measure's exclusion).
MIRROR_DISTANCE = measure.MIRROR_EXCLUSION
mirror_distance = measure.mirror_distance


def binned_error(theta_l, theta_v, phi, rendered, model, min_pixels=3, smooth=True):
    """The fidelity measure (``lut.render.measure``) on pixel samples of any
    geometry (e.g. the pixels of spheres under a sun, each its own (θl, θv,
    φ)): the samples are binned on the measure's grid (bin centres at its
    geometries; ``smooth``: samples within ``MIRROR_DISTANCE`` of the mirror
    direction left out), each bin's mean rendered and model radiance
    compared, every bin counted once:
    sqrt(Σ |mean rendered − mean model|² / Σ |mean model|²)
    over bins with at least ``min_pixels`` samples, all channels.
    ``rendered`` and ``model`` are radiances (N, 3) per unit irradiance
    (f·cos θl).  Returns (error, bins used)."""
    theta_l, theta_v, phi = (np.asarray(a, dtype=float).ravel() for a in (theta_l, theta_v, phi))
    rendered = np.asarray(rendered, dtype=float).reshape(theta_l.size, -1)
    model = np.asarray(model, dtype=float).reshape(theta_l.size, -1)
    ph = np.abs(phi)
    axes = measure.GRID
    steps = [a[1] - a[0] for a in axes]
    inside = np.ones(theta_l.shape, dtype=bool)
    index = []
    for value, axis, step in zip((theta_l, theta_v, ph), axes, steps, strict=True):
        inside &= (value >= axis[0] - step / 2) & (value <= axis[-1] + step / 2)
        index.append(np.clip(np.rint((value - axis[0]) / step), 0, axis.size - 1).astype(int))
    if smooth:
        inside &= mirror_distance(theta_l, theta_v, phi) >= MIRROR_DISTANCE
    shape = tuple(a.size for a in axes)
    flat = np.ravel_multi_index(tuple(index), shape)[inside]
    size = int(np.prod(shape))
    count = np.bincount(flat, minlength=size)
    used = count >= min_pixels
    if not used.any():
        raise ValueError("no bin of the measure holds enough samples")
    num = den = 0.0
    for c in range(rendered.shape[1]):
        got = np.bincount(flat, rendered[inside, c], size)[used] / count[used]
        want = np.bincount(flat, model[inside, c], size)[used] / count[used]
        num += np.sum((got - want) ** 2)
        den += np.sum(want**2)
    return float(np.sqrt(num / den)), int(used.sum())


def binned_errors(theta_l, theta_v, phi, rendered, model, min_pixels=3, smooth=True):
    """``binned_error`` whole and over the measure's grazing band (the bins
    of θl >= ``measure.GRAZING``): (whole, grazing or None where no bin of
    the band holds enough samples, bins used)."""
    theta_l = np.asarray(theta_l, dtype=float).ravel()
    whole, bins = binned_error(theta_l, theta_v, phi, rendered, model, min_pixels, smooth)
    step = measure.GRID[0][1] - measure.GRID[0][0]
    band = theta_l >= measure.GRAZING - step / 2  # the samples of the band's bins
    pick = [np.asarray(a, dtype=float).reshape(theta_l.size, -1)[band] for a in (theta_v, phi, rendered, model)]
    try:
        grazing = binned_error(theta_l[band], pick[0][:, 0], pick[1][:, 0], pick[2], pick[3], min_pixels, smooth)[0]
    except ValueError:
        grazing = None
    return whole, grazing, bins
