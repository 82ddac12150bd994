"""Stress test: finite, non-negative, continuous values at every numerical
edge, with no numpy warnings (pytest turns warnings into errors)."""

import numpy as np
import pytest

from lut import models

HALF = np.pi / 2
THETA = np.array([0.0, 1e-12, 1e-6, 0.3, np.pi / 3, HALF - 1e-3, HALF - 1e-9, HALF - 1e-13, HALF, 2.0, np.pi])
PHI = np.array([0.0, 1e-12, -1e-12, 0.7, np.pi - 1e-12, np.pi, -np.pi, 3 * np.pi])
TI, TS, PS = np.meshgrid(THETA, THETA, PHI, indexing="ij")


def _cases():
    for n in (1.0, 1.0 + 1e-9, 1.5, 3.0, 0.7):
        yield models.smooth_diffuse, {"n": n, "rho": 1.0}
        yield models.smooth_diffuse, {"n": n, "rho": 0.0}
        for g in (0.0, 0.999999, -0.999999):
            yield models.smooth_single, {"n": n, "g": g}
        for dist in ("gaussian", "exponential"):
            for slope in (1e-9, 1e-3, 0.25, 3.0):
                kw = {"n": n, "slope": slope, "distribution": dist}
                yield models.facet_reflection, kw
                yield models.facet_transmission, kw
                yield models.rough_diffuse, {**kw, "rho": 1.0}
                # Edge handling does not depend on the quadrature size: keep it small.
                yield models.rough_single, {**kw, "g": 0.999999, "nodes": (2, 4)}
                yield models.rough_single, {**kw, "g": -0.999999, "nodes": (2, 4)}


CASES = list(_cases())


@pytest.mark.parametrize(("fn", "kw"), CASES, ids=[f"{f.__name__}-{k}" for f, k in CASES])
def test_finite_and_non_negative_everywhere(fn, kw):
    m = fn(TI, TS, PS, **kw)
    assert m.shape == TI.shape + (4, 4)
    assert np.all(np.isfinite(m))
    assert np.all(m[..., 0, 0] >= 0.0)
    # Physical Mueller matrices: no element exceeds M00.
    assert np.all(np.abs(m) <= m[..., 0, 0][..., None, None] * (1 + 1e-9) + 1e-300)
    below = (TI >= HALF) | (TS >= HALF)
    assert np.all(m[below] == 0.0)


SMOOTH_AND_ROUGH = [
    (models.facet_reflection, {"n": 1.5, "slope": 0.3}),
    (models.facet_transmission, {"n": 1.5, "slope": 0.3}),
    (models.smooth_diffuse, {"n": 1.5, "rho": 0.7}),
    (models.smooth_single, {"n": 1.5, "g": 0.3}),
    (models.rough_diffuse, {"n": 1.5, "rho": 0.7, "slope": 0.3}),
    (models.rough_single, {"n": 1.5, "g": 0.3, "slope": 0.3}),
]


@pytest.mark.parametrize(("fn", "kw"), SMOOTH_AND_ROUGH, ids=lambda v: getattr(v, "__name__", ""))
def test_continuous_at_normal_incidence_and_in_plane(fn, kw):
    """s/p bases are undefined at normal incidence and the plane of incidence
    is special at φ = 0, π: values there join their neighbours.  (At θs = 0
    the exit basis is the limit along φs, so every element is continuous
    there at every φ: tests/test_normal_basis.py.)"""
    ts, ps = np.array([0.2, 0.9, 0.5, 0.5]), np.array([0.4, 2.5, 0.0, np.pi])
    for dt in (1e-9,):
        a = fn(0.0, ts, ps, **kw)
        b = fn(dt, ts, ps, **kw)
        np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-6 * np.max(a[..., 0, 0]))
    for phi in (0.0, np.pi):
        a = fn(0.6, 0.4, phi, **kw)
        b = fn(0.6, 0.4, phi + 1e-9, **kw)
        np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-6 * a[0, 0])
    a = fn(0.6, 0.0, 0.0, **kw)
    b = fn(0.6, 1e-9, 0.0, **kw)
    np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-6 * a[0, 0])
    m0 = fn(0.6, 0.0, np.array([0.0, 1.0, 2.0]), mueller=False, **kw)
    m1 = fn(0.6, 1e-9, np.array([0.0, 1.0, 2.0]), mueller=False, **kw)
    np.testing.assert_allclose(m0, m1, rtol=1e-6)


def test_backscatter_direction_is_regular():
    """k1 × k2 = 0 (Eq. 3) at exact retro-reflection: no σ/π basis is needed."""
    for fn, kw in ((models.smooth_single, {}), (models.rough_single, {"slope": 0.2})):
        a = fn(0.7, 0.7, np.pi, n=1.5, g=-0.5, **kw)
        b = fn(0.7, 0.7 + 1e-9, np.pi - 1e-9, n=1.5, g=-0.5, **kw)
        np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-7 * a[0, 0])


def test_index_tends_to_one():
    """n -> 1: the interface disappears; facet reflection vanishes and the
    smooth models join their n = 1 values."""
    ti, ts, ps = np.array([0.1, 0.8]), np.array([0.5, 1.2]), np.array([0.3, 2.0])
    assert np.all(models.facet_reflection(ti, ts, ps, n=1.0, slope=0.3) == 0.0)
    assert np.max(models.facet_reflection(ti, ts, ps, n=1.0 + 1e-6, slope=0.3, mueller=False)) < 1e-12
    for fn, kw in ((models.smooth_diffuse, {"rho": 0.5}), (models.smooth_single, {"g": 0.2})):
        a, b = fn(ti, ts, ps, n=1.0 + 1e-9, **kw), fn(ti, ts, ps, n=1.0, **kw)
        np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-7 * np.max(b[..., 0, 0]))
    # Transmission near the forward direction (D -> 0 in Eq. 32) stays finite.
    tt = np.radians(40.0) + np.array([0.0, 1e-12, 1e-6, 1e-3])
    f = models.facet_transmission(np.radians(40.0), tt, 0.0, n=1.0 + 1e-6, slope=0.1)
    assert np.all(np.isfinite(f))


def test_large_g_and_slopes_stay_continuous():
    ti, ts, ps = 0.5, np.linspace(0.0, 1.5, 31), 0.0
    for sign in (1.0, -1.0):
        # Near |g| = 1 the peak scales with 1/(1 - |g|): perturb 1 - |g| by 1e-6.
        a = models.smooth_single(ti, ts, ps, n=1.5, g=sign * (1 - 1e-6), mueller=False)
        b = models.smooth_single(ti, ts, ps, n=1.5, g=sign * (1 - 1e-6 * (1 + 1e-6)), mueller=False)
        np.testing.assert_allclose(a, b, rtol=1e-5)
    a = models.rough_single(ti, ts, ps, n=1.5, g=0.3, slope=3.0, mueller=False)
    b = models.rough_single(ti, ts, ps, n=1.5, g=0.3, slope=3.0 * (1 + 1e-6), mueller=False)
    np.testing.assert_allclose(a, b, rtol=1e-4)
    # slope -> 0 joins slope = 0 (the smooth model).
    for fn, kw in ((models.rough_single, {"g": 0.3}), (models.rough_diffuse, {"rho": 0.4})):
        np.testing.assert_allclose(
            fn(ti, ts, ps, n=1.5, slope=1e-9, **kw), fn(ti, ts, ps, n=1.5, slope=0.0, **kw), rtol=1e-8, atol=1e-14
        )


def test_rough_models_are_smooth_in_angle_and_deterministic():
    """Quadrature nodes move continuously with direction: no sampling noise.
    Second differences of a fine in-plane scan are those of a smooth curve."""
    ts = np.linspace(0.05, 1.4, 271)
    for dist, slope in (("gaussian", 0.25), ("exponential", 2.0)):
        f = models.rough_single(0.6, ts, 0.0, n=1.5, g=0.3, slope=slope, distribution=dist, mueller=False)
        np.testing.assert_array_equal(
            f, models.rough_single(0.6, ts, 0.0, n=1.5, g=0.3, slope=slope, distribution=dist, mueller=False)
        )
        second = np.abs(np.diff(f, 2)) / f[1:-1]
        assert np.max(second) < 1e-3
