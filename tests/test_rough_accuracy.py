"""The rough models' default quadrature against a converged reference: the
documented defaults must reach <= 0.5% relative RMS error (docs/models.md)."""

import numpy as np
import pytest
from helpers import relative_rms

from lut import models
from lut.models import rough

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
