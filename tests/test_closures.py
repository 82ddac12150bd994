"""lut.closures: the per-view closure fit (numpy side)."""

import numpy as np
import pytest

import lut
from lut import closures


def test_nnls_matches_scipy():
    optimize = pytest.importorskip("scipy.optimize")
    rng = np.random.default_rng(2)
    for _ in range(20):
        a, b = rng.random((50, 10)), rng.random(50) - 0.4
        x = closures.nnls(a, b)
        assert np.all(x >= 0)
        np.testing.assert_allclose(x, optimize.nnls(a, b)[0], atol=1e-10)


def test_toon_closures_integrate_to_their_cone():
    """A Toon closure with no smoothing is a uniform cone: its hemispherical
    integral of the contribution (cos included) over directions is 1."""
    closure = closures.Closure("diffuse_toon", 0.5, 0.0)
    theta = np.linspace(0, np.pi / 2, 200_001)
    value = closure.evaluate(theta, 0.3, 0.0)
    y = value * np.sin(theta)
    integral = np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(theta)) * 2 * np.pi  # trapezoid rule
    assert integral == pytest.approx(1.0, rel=1e-3)


@pytest.mark.parametrize("name", ["glossy_white", "custom"])
def test_smooth_paints_fit_within_one_percent(name):
    paint = lut.preset("glossy_white") if name == "glossy_white" else lut.Paint(rho=(0.8, 0.4, 0.1), single=0.3, g=0.3)
    fitted = closures.fit(paint)
    assert fitted.error < 0.01
    assert np.all(fitted.weights >= 0) and fitted.weights.shape == (len(fitted.basis), 32, 3)
    assert np.all(fitted.weights.max(axis=(1, 2)) > 0)  # unused closures are dropped
    assert fitted.mirror == paint.facet


def test_rough_paints_get_metallic_lobes():
    satin = closures.basis_for(lut.Paint(slope=0.25, n=1.4))
    assert [c for c in satin if c.grey] == [closures.Closure("metallic", ior=1.4, roughness=0.5)]
    matte = closures.basis_for(lut.Paint(slope=2.0, distribution="exponential"))
    assert len([c for c in matte if c.grey]) == 4
    fitted = closures.fit(lut.Paint(rho=0.5, slope=0.25))
    grey = [k for k, c in enumerate(fitted.basis) if c.grey]
    np.testing.assert_array_equal(fitted.weights[grey, :, 0], fitted.weights[grey, :, 2])  # one weight for all channels
    assert fitted.weights[grey].max() <= 1.0  # a Mix Shader factor
    assert fitted.mirror == 0.0


def test_metallic_closure_without_shadowing_is_the_facet_term():
    closure = closures.Closure("metallic", ior=1.5, roughness=0.5)
    theta_l, theta_v, phi = np.radians([20.0, 40.0]), np.radians([30.0, 35.0]), np.array([0.2, 1.0])
    facet = lut.models.facet_reflection(theta_l, theta_v, phi, n=1.5, slope=0.25, mueller=False) * np.cos(theta_l)
    value = closure.evaluate(theta_l, theta_v, phi)
    assert np.all(value <= facet) and np.all(value > 0.99 * facet)  # G is just below 1 here


def test_weights_file_is_written_bottom_up(tmp_path):
    fitted = closures.fit(lut.Paint(rho=0.5))
    path = closures.save_weights(fitted, tmp_path / "w.exr")
    oiio = lut.lutfile._oiio()
    pixels = oiio.ImageBuf(str(path)).get_pixels(oiio.FLOAT)
    np.testing.assert_allclose(pixels[-1], fitted.weights[0], rtol=1e-6)  # closure 0 in the bottom row


def test_closure_budget_keeps_the_strongest():
    paint = lut.preset("green_carc")
    full = closures.fit_all(paint)
    budget = closures.fit(paint, max_closures=4)
    assert len(full.basis) > 4 and len(budget.basis) <= 4
    assert set(budget.basis) <= set(full.basis)
    assert budget.error < 2 * full.error  # the strongest closures carry most of the fit
    with pytest.raises(ValueError, match="max_closures must be a whole number >= 1"):
        closures.fit(paint, max_closures=0)


def test_blender_4_lobes_keep_the_facet_weight():
    """Without an exact Metallic BSDF (Blender 4.2-4.5) a Gaussian facet
    term becomes one GGX lobe of the same alpha whose weight is the paint's
    facet weight at every view; the rest is fitted around it."""
    paint = lut.Paint(rho=0.5, slope=0.05, facet=0.8)
    basis = closures.basis_for(paint, exact_metallic=False)
    assert [c for c in basis if c.grey] == [closures.Closure("ggx", ior=1.5, roughness=np.sqrt(0.05), fixed=0.8)]
    fitted = closures.fit(paint, exact_metallic=False)
    k = next(k for k, c in enumerate(fitted.basis) if c.kind == "ggx")
    np.testing.assert_array_equal(fitted.weights[k], 0.8)
    assert len(fitted.basis) <= closures.MAX_CLOSURES
    eevee = closures.basis_for(paint, target="EEVEE")
    assert {c.kind for c in eevee} == {"lambert", "metallic"}
    with pytest.raises(ValueError, match="target must be one of CYCLES, EEVEE"):
        closures.basis_for(paint, target="WORKBENCH")
