"""Physics the models must obey: reciprocity, energy balance, the paper's
statements about Figs. 1 and 2, and the smooth limit of the rough models."""

import numpy as np
import pytest
from helpers import hemispherical, relative_rms

from lut import figures, models
from lut.models import fresnel, geometry, phase, reference

RNG = np.random.default_rng(7)
TI = RNG.uniform(0.0, 1.45, 120)
TS = RNG.uniform(0.0, 1.45, 120)
PS = RNG.uniform(-np.pi, np.pi, 120)

REFLECTION = [
    (models.facet_reflection, {"n": 1.5, "slope": 0.3}),
    (models.facet_reflection, {"n": 1.33, "slope": 1.0, "distribution": "exponential"}),
    (models.smooth_diffuse, {"n": 1.5, "rho": 0.8}),
    (models.smooth_single, {"n": 1.5, "g": 0.6}),
    (models.rough_diffuse, {"n": 1.5, "rho": 0.8, "slope": 0.25}),
    (models.rough_single, {"n": 1.5, "g": 0.3, "slope": 0.25}),
    (models.rough_single, {"n": 1.5, "g": -0.3, "slope": 2.0, "distribution": "exponential"}),
]


@pytest.mark.parametrize(("fn", "kw"), REFLECTION, ids=lambda v: getattr(v, "__name__", str(v)))
def test_reciprocity_of_m00(fn, kw):
    """Helmholtz reciprocity: swapping source and viewer keeps M00 (in this
    geometry the swap keeps φs)."""
    forward = fn(TI, TS, PS, mueller=False, **kw)
    backward = fn(TS, TI, PS, mueller=False, **kw)
    assert np.all(forward > 0)
    np.testing.assert_allclose(forward, backward, rtol=1e-10)


@pytest.mark.parametrize(("fn", "kw"), REFLECTION, ids=lambda v: getattr(v, "__name__", str(v)))
def test_m00_only_path_equals_the_full_matrix(fn, kw):
    full = fn(TI, TS, PS, **kw)
    alone = fn(TI, TS, PS, mueller=False, **kw)
    assert full.shape == TI.shape + (4, 4)
    np.testing.assert_allclose(alone, full[..., 0, 0], rtol=1e-12, atol=0)


@pytest.mark.parametrize("theta_i", [0.0, 0.5, 1.0, 1.3])
@pytest.mark.parametrize("n", [1.33, 1.5, 2.0])
def test_white_substrate_under_smooth_interface_reflects_everything(theta_i, n):
    """Sec. 2.3: with ρ = 1 the diffuse term plus the specular Fresnel
    reflectance is exactly 1."""
    rs, rp = fresnel.reflection_coefficients(np.cos(theta_i), n)
    specular = 0.5 * (rs * rs + rp * rp)
    total = hemispherical(models.smooth_diffuse, theta_i, n=n, rho=1.0) + specular
    assert total == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize(
    ("slope", "distribution"), [(0.1, "gaussian"), (0.25, "gaussian"), (0.5, "gaussian"), (0.5, "exponential")]
)
@pytest.mark.parametrize("theta_i", [0.0, 0.5, 1.0])
def test_white_substrate_under_rough_interface_conserves_energy(slope, distribution, theta_i):
    """Facet reflection plus the diffuse term with ρ = 1 stays within
    [0.97, 1.02] at moderate slopes and angles (no shadowing in either)."""
    kw = {"n": 1.5, "slope": slope, "distribution": distribution}
    total = hemispherical(models.facet_reflection, theta_i, n_theta=128, n_phi=128, **kw) + hemispherical(
        models.rough_diffuse, theta_i, rho=1.0, **kw
    )
    assert 0.97 <= total <= 1.02


def test_internal_reflectance_is_the_exact_integral():
    """Eq. 22 by brute force (10⁶-point midpoint rule in the internal angle)."""
    m = 1_000_000
    theta = (np.arange(m) + 0.5) * (np.pi / 2) / m
    for n in (1.33, 1.5, 2.0, 0.8):
        sin_out = n * np.sin(theta)
        tir = sin_out >= 1.0
        c_out = np.sqrt(np.clip(1.0 - sin_out**2, 0.0, None))
        c_in = np.cos(theta)
        rs = (c_out - n * c_in) / (c_out + n * c_in)
        rp = (n * c_out - c_in) / (n * c_out + c_in)
        refl = np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))
        brute = np.sum(refl * np.sin(2.0 * theta)) * (np.pi / 2) / m
        # The midpoint rule's error at the critical-angle kink is O(h^1.5) ~ 2e-9.
        assert models.internal_reflectance(n) == pytest.approx(brute, abs=1e-8)
        assert models.internal_reflectance(n) == pytest.approx(models.internal_reflectance(n, 1024), abs=1e-14)
    assert models.internal_reflectance(1.5) == pytest.approx(0.596346, abs=5e-7)
    assert models.internal_reflectance(1.0) == 0.0


def test_henyey_greenstein_is_normalized_with_mean_cosine_g():
    x, w = np.polynomial.legendre.leggauss(400)
    for g in (-0.9, -0.3, 0.0, 0.5, 0.95):
        p = phase.henyey_greenstein(x, g)
        assert 2 * np.pi * np.sum(w * p) == pytest.approx(1.0, abs=1e-9)
        assert 2 * np.pi * np.sum(w * p * x) == pytest.approx(g, abs=1e-9)


def test_polarimetric_phase_function_m00_is_henyey_greenstein():
    """Eq. 7: M00 of 2p/(1 + cos²θ) M(J_vol), J_vol = diag(1, cos θ), is p."""
    c = np.linspace(-1, 1, 41)
    jones = np.zeros(c.shape + (2, 2))
    jones[..., 0, 0] = 1.0
    jones[..., 1, 1] = c
    m = phase.rayleigh_factor(c, 0.4)[..., None, None] * models.jones_to_mueller(jones)
    np.testing.assert_allclose(m[..., 0, 0], phase.henyey_greenstein(c, 0.4), rtol=1e-14)
    # Rayleigh polarization: fully polarized at 90°, M01/M00 = (1 - c²)/(1 + c²).
    np.testing.assert_allclose(m[..., 0, 1] / m[..., 0, 0], (1 - c * c) / (1 + c * c), atol=1e-14)


def test_transmission_jacobian_equals_eq39():
    """dΩn/dΩt = n² cos ι_t / D² is the paper's Eq. 39 in another form."""
    n = 1.5
    ti, tt, pt = RNG.uniform(0, 1.4, 200), RNG.uniform(0, 1.4, 200), RNG.uniform(-np.pi, np.pi, 200)
    k_i, k_t = geometry.incident(ti), geometry.transmitted(tt, pt)
    v = k_i - n * k_t  # Eq. 31: the facet normal is ±v/D, D = |v| (Eq. 32)
    d = np.sqrt(geometry.dot(v, v))
    h = v * np.sign(v[..., 2:3]) / d[..., None]
    ours = n * n * -geometry.dot(k_t, h) / d**2
    eq39 = (
        n
        * n
        * (
            -(n * (3 + np.cos(2 * tt)) * np.cos(ti))
            + np.cos(pt) * np.sin(2 * ti) * np.sin(tt)
            + np.cos(tt) * np.cos(ti) ** 2
            + np.cos(tt) * (1 - 2 * n * np.cos(pt) * np.sin(ti) * np.sin(tt) + 2 * n * n - np.sin(ti) ** 2)
        )
        / (2 * d**3 * (n * np.cos(tt) - np.cos(ti)))
    )
    np.testing.assert_allclose(np.abs(ours), np.abs(eq39), rtol=1e-10)


THETA_60 = np.radians(60.0)


def _in_plane_btdf(sigma, theta_i=THETA_60):
    tt = np.radians(np.linspace(0.0, 89.9, 3000))
    return tt, models.facet_transmission(theta_i, tt, 0.0, n=1.5, slope=sigma, mueller=False)


def test_fig1_narrow_distribution_peaks_near_36_degrees():
    """Fig. 1 (left): at θi = 60°, n = 1.5 the narrowest distribution peaks
    at θt ≈ 36°, close to the regular refraction angle 35.3°."""
    tt, f = _in_plane_btdf(0.1)
    assert np.degrees(tt[np.argmax(f)]) == pytest.approx(36.0, abs=0.5)


def test_fig1_peak_moves_towards_the_incident_angle_as_slopes_widen():
    peaks = [np.degrees(tt[np.argmax(f)]) for tt, f in map(_in_plane_btdf, (0.05, 0.1, 0.3, 0.5, 1.0))]
    assert np.all(np.diff(peaks) > 0)
    assert 35.2 < peaks[0] < 36.0
    assert 50.0 < peaks[-1] < 60.0


def test_fig1_mean_angle_follows_snell_then_a_lower_index():
    """Fig. 1 (right): for narrow slopes sin<θt> = sin θi / n; wider slopes
    follow Snell's law with a substantially lower effective index."""
    angles = np.radians([30.0, 50.0, 70.0])
    narrow = np.array([figures.mean_refraction_sine(a, 0.05) for a in angles]) / np.sin(angles)
    np.testing.assert_allclose(narrow, 1 / 1.5, rtol=0.01)
    n_eff = {s: np.sin(angles) / np.array([figures.mean_refraction_sine(a, s) for a in angles]) for s in (0.5, 1.0)}
    assert np.all(n_eff[0.5] < 1.36) and np.all(n_eff[0.5] > 1.2)
    assert np.all(n_eff[1.0] < n_eff[0.5]) and np.all(n_eff[1.0] > 1.0)


def test_fig2_glossy_white_is_p_polarized_and_more_polarized_at_large_angles():
    """Fig. 2 (left): totally diffuse scattering under a smooth interface has
    η = ±90° (an excess of p) and P rising at large angles."""
    ts = np.radians(np.linspace(5, 85, 17))
    q = models.polarization_parameters(models.smooth_diffuse(np.radians(60), ts, 0.0, n=1.5, rho=0.93))
    np.testing.assert_allclose(np.abs(q["eta"]), np.pi / 2, atol=1e-12)
    np.testing.assert_allclose(q["pc"], 0.0, atol=1e-15)
    assert np.all(np.diff(q["p"]) > 0)
    assert q["p"][-1] > 0.3 and q["p"][0] < 0.15


def test_fig2_facet_reflection_is_s_polarized_near_specular():
    """Near specular, facet reflection of 45° light has η near 0 (the
    Fresnel coefficients favour s), unlike the subsurface term."""
    q = models.polarization_parameters(models.facet_reflection(np.radians(60), np.radians(60), 0.0, n=1.5, slope=0.1))
    assert -np.pi / 4 < float(q["eta"]) < 0.0 or 0.0 <= float(q["eta"]) < np.pi / 4


@pytest.mark.parametrize(
    ("rough", "smooth", "kw"),
    [
        (models.rough_diffuse, models.smooth_diffuse, {"rho": 0.9}),
        (models.rough_single, models.smooth_single, {"g": 0.3}),
        (models.rough_single, models.smooth_single, {"g": -0.7}),
    ],
)
def test_rough_models_tend_to_their_smooth_counterparts(rough, smooth, kw):
    """As slope -> 0 every Mueller element converges (as slope²), and at slope
    0.01 the hemispherical reflectance is within 1%."""
    ref = smooth(TI, TS, PS, n=1.5, **kw)
    errors = []
    for s in (1e-2, 1e-3):
        got = rough(TI, TS, PS, n=1.5, slope=s, **kw)
        errors.append(np.max(np.abs(got - ref)) / np.max(ref[..., 0, 0]))
    assert errors[0] < 2e-3 and errors[1] < errors[0] / 50
    for ti in (0.2, 1.0):
        h_rough = hemispherical(rough, ti, n=1.5, slope=0.01, **kw)
        h_smooth = hemispherical(smooth, ti, n=1.5, **kw)
        assert h_rough == pytest.approx(h_smooth, rel=0.01)


def test_rough_internal_reflectance_tends_to_eq22():
    assert models.rough_internal_reflectance(1.5, 1e-3, "gaussian") == pytest.approx(
        models.internal_reflectance(1.5), abs=1e-6
    )
    # Rough interfaces let more diffuse light out than smooth ones.
    assert models.rough_internal_reflectance(1.5, 0.5, "gaussian") < models.internal_reflectance(1.5)


def test_rough_diffuse_is_depolarizing_and_azimuth_free():
    m = models.rough_diffuse(TI, TS, PS, n=1.5, rho=0.5, slope=0.4)
    np.testing.assert_allclose(m, models.rough_diffuse(TI, TS, 0.0, n=1.5, rho=0.5, slope=0.4), rtol=1e-13)
    # U and V vanish by the mirror symmetry of the visible facets, which the
    # quadrature keeps to rounding.
    scale = m[..., 0, 0][..., None]
    assert np.max(np.abs(m[..., 2:, :]) / scale[..., None]) < 1e-12
    assert np.max(np.abs(m[..., :, 2:]) / scale[..., None]) < 1e-12
    # Exit column and entry row are the same functions (reciprocity).
    np.testing.assert_allclose(m[..., 1, 0] * m[..., 0, 1], m[..., 0, 0] * m[..., 1, 1], rtol=1e-10, atol=1e-18)


def test_random_pairs_method_agrees_with_the_quadrature():
    """The paper's Monte Carlo average converges to the same M00."""
    kw = {"n": 1.5, "g": 0.3, "slope": 0.25}
    ref = models.rough_single(TI[:40], TS[:40], PS[:40], mueller=False, nodes=(12, 16), **kw)
    mc = reference.rough_single_random(TI[:40], TS[:40], PS[:40], pairs=4000, seed=3, **kw)
    assert relative_rms(mc, ref) < 0.01


def test_example_reproduces_fig2_statements():
    from lut import examples

    data = examples.fig2_glossy_white()
    polarized = data["p"] > 1e-12
    np.testing.assert_allclose(np.abs(data["eta"][polarized]), np.pi / 2, atol=1e-12)
    assert np.all(np.isnan(data["eta"][~polarized]))
    assert np.all(data["fr"] > 0) and data["fr"][0] < 0.5 * data["fr"].max()
