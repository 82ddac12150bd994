"""The angular table behind a LUT: the polarization-averaged BRDF on a grid of
Rusinkiewicz half/difference angles (``lut.lutfiles.angles``), and its interpolation.

Axes (nodes include both ends):
  u  in [0, 1] with θh = (π/2)·u²: the square-root spacing of the half angle
     puts nodes densely near θh = 0, where facet lobes are sharp (a lobe of
     RMS slope s is about s radians wide in θh; with 64 nodes the first step
     is 0.02°);
  θd in [0, π/2], uniform;
  φd in [0, π/2], uniform (isotropy, reciprocity and mirror symmetry fold
     every φd there; ``lut.lutfiles.angles``).
The table stores G = f · cos θi · cos θs rather than f: the facet term's
1/(cos θi cos θs) would otherwise vary steeply along θd near the horizon,
while G is smooth for every term.  Nodes below the horizon store G continued
from the horizon (polar angles clamped to HORIZON_CLAMP), so cells straddling
it interpolate smoothly.  Lookup is trilinear in (u, θd, φd), then divides
by cos θi cos θs; it returns 0 at or below the horizon.
"""

from __future__ import annotations

import concurrent.futures
import os

import numpy as np

from . import angles

#: Default (N_u, N_θd, N_φd): see docs/lut.md for the error it reaches.
DEFAULT_RESOLUTION = (64, 32, 16)
HALF_PI = np.pi / 2
#: Polar angle at which nodes below the horizon are evaluated.
HORIZON_CLAMP = np.radians(89.0)


def axes(resolution):
    """Node coordinates (θh, θd, φd) of a resolution (N_u, N_θd, N_φd)."""
    n_u, n_d, n_p = resolution
    u = np.linspace(0.0, 1.0, n_u)
    return HALF_PI * u * u, np.linspace(0.0, HALF_PI, n_d), np.linspace(0.0, HALF_PI, n_p)


def node_directions(resolution):
    """(θi, θs, φs) of every node, shape (N_φd, N_θd, N_u), with polar angles
    clamped to HORIZON_CLAMP (the continuation below the horizon)."""
    th, td, pd = axes(resolution)
    ti, ts, ps = angles.from_half_diff(th[None, None, :], td[None, :, None], pd[:, None, None])
    return np.minimum(ti, HORIZON_CLAMP), np.minimum(ts, HORIZON_CLAMP), ps


def default_workers() -> int:
    """Threads a bake uses: one per core, at most four (numpy releases the
    interpreter lock inside its array operations, so chunks run in parallel)."""
    return max(1, min(4, os.cpu_count() or 1))


def tabulate(brdf, resolution, chunk=4096, progress=None, channels=3, workers=None):
    """G = brdf · cos θi · cos θs at every node, ``brdf(θi, θs, φs) -> (..., channels)``
    evaluated in chunks on ``workers`` threads (default ``default_workers``),
    calling progress(done, total) on the calling thread as chunks finish (it
    may raise to stop: chunks not started are dropped).  Returns float32
    (N_φd, N_θd, N_u, channels)."""
    ti, ts, ps = (a.ravel() for a in node_directions(resolution))
    out = np.empty((ti.size, channels), dtype=np.float32)
    starts = range(0, ti.size, chunk)

    def run(start):
        sl = slice(start, start + chunk)
        out[sl] = brdf(ti[sl], ts[sl], ps[sl]) * (np.cos(ti[sl]) * np.cos(ts[sl]))[:, None]
        return min(start + chunk, ti.size) - start

    workers = default_workers() if workers is None else max(1, int(workers))
    done = 0
    if workers == 1:
        for start in starts:
            done += run(start)
            if progress is not None:
                progress(done, ti.size)
    else:
        pool = concurrent.futures.ThreadPoolExecutor(max_workers=workers, thread_name_prefix="paint-lut-table")
        try:
            for future in concurrent.futures.as_completed([pool.submit(run, start) for start in starts]):
                done += future.result()
                if progress is not None:
                    progress(done, ti.size)
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
    n_u, n_d, n_p = resolution
    return out.reshape(n_p, n_d, n_u, channels)


def interpolate(table, theta_i, theta_s, phi_s):
    """The BRDF at model angles from a table of G (N_φd, N_θd, N_u, C):
    trilinear lookup divided by cos θi cos θs; zero at or below the horizon.
    Returns broadcast(angles) + (C,)."""
    n_p, n_d, n_u, _ = table.shape
    ti, ts, ps = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_i, theta_s, phi_s)))
    th, td, pd = angles.to_half_diff(ti, ts, ps)
    coords = (
        np.clip(pd / HALF_PI, 0.0, 1.0) * (n_p - 1),
        np.clip(td / HALF_PI, 0.0, 1.0) * (n_d - 1),
        np.sqrt(np.clip(th / HALF_PI, 0.0, 1.0)) * (n_u - 1),
    )
    out = trilinear(table, coords)
    up = (ti < HALF_PI) & (ts < HALF_PI)
    cos2 = np.where(up, np.cos(ti) * np.cos(ts), 1.0)
    return np.where(up[..., None], out / cos2[..., None], 0.0)


def trilinear(table, coords):
    """Trilinear interpolation of a table (N_a, N_b, N_c, C) at fractional
    node coordinates (a, b, c) (each of one shape, within the table):
    returns that shape + (C,)."""
    lo, frac = [], []
    for c, size in zip(coords, table.shape[:3], strict=True):
        i = np.minimum(np.floor(c).astype(np.intp), max(size - 2, 0))
        lo.append(i)
        frac.append((c - i)[..., None] if size > 1 else np.zeros(c.shape + (1,)))
    out = np.zeros(np.shape(coords[0]) + (table.shape[-1],))
    for dp in (0, 1):
        wp = frac[0] if dp else 1.0 - frac[0]
        for dd in (0, 1):
            wd = frac[1] if dd else 1.0 - frac[1]
            for du in (0, 1):
                wu = frac[2] if du else 1.0 - frac[2]
                ip = np.minimum(lo[0] + dp, table.shape[0] - 1)
                idd = np.minimum(lo[1] + dd, table.shape[1] - 1)
                iu = np.minimum(lo[2] + du, table.shape[2] - 1)
                out += wp * wd * wu * table[ip, idd, iu]
    return out
