"""The vectorization helpers agree with the direct formulas they replace."""

import numpy as np

from lut import models
from lut.models import _vectorize

RNG = np.random.default_rng(5)


def test_rotated_interface_mueller_equals_the_jones_product():
    n = 500
    a, b = RNG.uniform(-3, 3, n), RNG.uniform(-3, 3, n)
    rot = (np.cos(a), np.sin(a), np.cos(b), np.sin(b))
    r_in = np.moveaxis(np.array([[rot[0], rot[1]], [-rot[1], rot[0]]]), -1, 0)
    r_out = np.moveaxis(np.array([[rot[2], -rot[3]], [rot[3], rot[2]]]), -1, 0)
    for c_s, c_p in (
        (RNG.normal(size=n), RNG.normal(size=n)),
        (RNG.normal(size=n) + 1j * RNG.normal(size=n), RNG.normal(size=n) + 1j * RNG.normal(size=n)),
    ):
        diag = np.zeros((n, 2, 2), dtype=c_s.dtype)
        diag[:, 0, 0], diag[:, 1, 1] = c_s, c_p
        expected = models.jones_to_mueller(r_out @ diag @ r_in)
        np.testing.assert_allclose(_vectorize.rotated_interface_mueller(c_s, c_p, *rot), expected, atol=1e-13)


def test_cheap_sines_are_accurate():
    theta = np.concatenate([np.linspace(0, np.pi / 2, 200_001), [1e-300, 1e-9, 0.1 - 1e-12, 0.1, 0.1 + 1e-12]])
    c, s = _vectorize.cos_sin_polar(theta)
    np.testing.assert_array_equal(c, np.cos(theta))
    np.testing.assert_allclose(s, np.sin(theta), rtol=5e-14, atol=0)
    phi = np.concatenate([RNG.uniform(-50, 50, 100_000), np.pi * np.arange(-7, 8), [1e-12, -1e-12]])
    c, s = _vectorize.cos_sin_azimuth(phi)
    np.testing.assert_allclose(c, np.cos(phi), atol=1e-14)
    np.testing.assert_allclose(s, np.sin(phi), atol=1e-14)
    assert np.all(np.sign(s[np.abs(np.sin(phi)) > 1e-10]) == np.sign(np.sin(phi)[np.abs(np.sin(phi)) > 1e-10]))


def test_grid_axes_and_full_arrays_give_the_same_values():
    """Trigonometry hoisted out of a broadcast grid changes nothing."""
    ti = np.linspace(0.0, 1.5, 7)[:, None, None]
    ts = np.linspace(0.0, 1.5, 6)[None, :, None]
    ps = np.linspace(-np.pi, np.pi, 5)[None, None, :]
    full = np.broadcast_arrays(ti, ts, ps)
    for fn, kw in (
        (models.facet_reflection, {"n": 1.5, "slope": 0.3}),
        (models.facet_transmission, {"n": 1.5, "slope": 0.3}),
        (models.smooth_diffuse, {"n": 1.5, "rho": 0.7}),
        (models.smooth_single, {"n": 1.5, "g": 0.3}),
    ):
        np.testing.assert_array_equal(fn(ti, ts, ps, **kw), fn(*(a.copy() for a in full), **kw))


def test_blocked_evaluation_matches_one_block(monkeypatch):
    ti, ts, ps = RNG.uniform(0, 1.5, 3001), RNG.uniform(0, 1.5, 3001), RNG.uniform(-4, 4, 3001)
    ref = models.facet_transmission(ti, ts, ps, n=1.5, slope=0.4)
    monkeypatch.setattr(_vectorize, "BLOCK", 97)
    np.testing.assert_array_equal(models.facet_transmission(ti, ts, ps, n=1.5, slope=0.4), ref)
