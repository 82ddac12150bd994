"""The rough models' default quadrature against a converged reference: the
documented defaults must reach <= 0.5% relative RMS error (docs/models.md)."""

import numpy as np
import pytest
from helpers import relative_rms

from lut import models
from lut.models import distributions, rough

RNG = np.random.default_rng(11)
TI = RNG.uniform(0.0, np.radians(80), 80)
TS = RNG.uniform(0.0, np.radians(80), 80)
PS = RNG.uniform(-np.pi, np.pi, 80)

PAINTS = [
    ("gaussian", 0.1),
    ("gaussian", 0.25),
    ("gaussian", 1.0),
    ("exponential", 0.5),
    ("exponential", 2.0),
]


@pytest.mark.parametrize(("distribution", "slope"), PAINTS)
def test_rough_single_defaults_within_half_a_percent(distribution, slope):
    kw = {"n": 1.5, "g": 0.3, "slope": slope, "distribution": distribution, "mueller": False}
    converged = models.rough_single(TI, TS, PS, nodes=(12, 16), **kw)
    finer = models.rough_single(TI[:20], TS[:20], PS[:20], nodes=(16, 24), **kw)
    assert relative_rms(finer, converged[:20]) < 5e-4  # the reference itself has converged
    assert relative_rms(models.rough_single(TI, TS, PS, **kw), converged) < 5e-3


@pytest.mark.parametrize(("distribution", "slope"), PAINTS)
def test_rough_diffuse_defaults_within_half_a_percent(distribution, slope):
    kw = {"n": 1.5, "rho": 0.8, "slope": slope, "distribution": distribution}
    converged = models.rough_diffuse(TI, TS, PS, nodes=(48, 48), **kw)
    assert relative_rms(models.rough_diffuse(TI, TS, PS, **kw), converged) < 5e-3
    assert relative_rms(models.rough_diffuse(TI, TS, PS, **kw)[..., 1, 0], converged[..., 1, 0]) < 5e-3


def test_rough_diffuse_table_path_matches_direct_path(monkeypatch):
    """Many distinct angles go through a fine table with linear
    interpolation; it agrees with direct evaluation."""
    kw = {"n": 1.5, "rho": 0.8, "slope": 0.3}
    direct = models.rough_diffuse(TI, TS, PS, **kw)
    monkeypatch.setattr(rough, "DIRECT_LIMIT", 10)
    tabulated = models.rough_diffuse(TI, TS, PS, **kw)
    scale = direct[..., 0, 0][..., None, None]
    assert np.max(np.abs(tabulated - direct) / scale) < 1e-5


def test_rough_single_mueller_elements_converge():
    kw = {"n": 1.5, "g": 0.3, "slope": 0.25}
    converged = models.rough_single(TI[:30], TS[:30], PS[:30], nodes=(12, 16), **kw)
    default = models.rough_single(TI[:30], TS[:30], PS[:30], **kw)
    scale = converged[..., 0, 0][..., None, None]
    assert np.sqrt(np.mean(((default - converged) / scale) ** 2)) < 5e-3


WIDE = [("gaussian", 1.2), ("gaussian", 3.0), ("exponential", 0.77), ("exponential", 3.0)]


@pytest.mark.parametrize(("distribution", "slope"), WIDE)
def test_rough_single_defaults_within_0_3_percent_at_wide_slopes_and_normal_incidence(distribution, slope):
    """Worst case, not RMS: normal incidence and wide slopes are where the
    radial rule used to lose accuracy (the e^-t factor resolved by
    Gauss-Legendre, half the nodes far in the tail)."""
    rng = np.random.default_rng(5)
    ti = np.concatenate(([0.0, 0.0, 0.0, 0.05], rng.uniform(0.0, np.radians(80), 8)))
    ts = np.concatenate(([0.3, 0.9, 1.2, 0.0], rng.uniform(0.0, np.radians(80), 8)))
    ps = rng.uniform(-np.pi, np.pi, ti.size)
    kw = {"n": 1.55, "g": 0.6, "slope": slope, "distribution": distribution, "mueller": False}
    converged = models.rough_single(ti, ts, ps, nodes=(16, 32), **kw)
    default = models.rough_single(ti, ts, ps, **kw)
    assert np.max(np.abs(default / converged - 1.0)) < 3e-3


@pytest.mark.parametrize("distribution", ["gaussian", "exponential"])
def test_split_radial_rule_is_gauss_on_each_piece_and_continuous(distribution):
    """Each piece integrates its measure's polynomials exactly (in t inside,
    in v = √(t - t_split) outside, so a (t - t_split)^(3/2) kink too), and
    the nodes move continuously with the split point."""
    nodes, slope = 4, 1.3
    t_split = np.array([0.0, 1e-9, 0.01, 0.37, 1.0, 1.9, 3.5, 50.0])
    zeta, w = distributions.split_radial_rule(t_split, slope, distribution, nodes)
    t = distributions.radial_variable(zeta, slope, distribution)
    ts = np.minimum(t_split, distributions._T_CAP[distribution])[:, None]
    inner, outer = t[:, :nodes], t[:, nodes:]
    w_in, w_out = w[:, :nodes], w[:, nodes:]
    assert np.all((inner <= ts + 1e-12) & (outer >= ts - 1e-12))
    x, wx = np.polynomial.legendre.leggauss(200)
    measure = (lambda u: np.exp(-u)) if distribution == "gaussian" else (lambda u: u * np.exp(-u))
    for k in range(2 * nodes):
        u = 0.5 * ts * (x + 1.0)  # inner: ∫_0^ts t^k measure dt
        exact_in = np.sum(0.5 * ts * wx * u**k * measure(u), axis=-1)
        np.testing.assert_allclose(np.sum(w_in * inner**k, axis=-1), exact_in, rtol=1e-6, atol=1e-14)
        v = 3.5 * (x + 1.0)  # outer: ∫_0^∞ v^k measure(ts + v²) 2v dv
        exact_out = np.sum(3.5 * wx * v**k * measure(ts + v * v) * 2.0 * v, axis=-1)
        got = np.sum(w_out * np.sqrt(np.clip(outer - ts, 0.0, None)) ** k, axis=-1)
        np.testing.assert_allclose(got, exact_out, rtol=1e-6, atol=1e-14)
    a = distributions.split_radial_rule(np.array([0.7, 0.7 + 1e-9]), slope, distribution, nodes)
    np.testing.assert_allclose(a[0][0], a[0][1], rtol=0, atol=1e-7)
    np.testing.assert_allclose(a[1][0], a[1][1], rtol=0, atol=1e-7)
