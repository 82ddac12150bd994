"""One polarization basis for a ray along the normal, in every model: the
limit of s = ẑ×k/|ẑ×k| along the ray's azimuth (docs/models.md, Conventions).
At normal exit the Mueller matrix then rotates with φs exactly as that change
of basis predicts, and joins its neighbours θs -> 0 at every φs."""

import numpy as np
import pytest
from helpers import normal_basis_rotation

from lut import models

PHI = np.array([0.7, -1.9, 2.6, np.pi / 2, -0.0708, 3.0])

CLOSED_FORM = [
    (models.facet_reflection, {"n": 1.6076, "slope": 0.0523}),
    (models.facet_reflection, {"n": 1.5, "slope": 0.8, "distribution": "exponential"}),
    (models.facet_transmission, {"n": 1.5, "slope": 0.3}),
    (models.facet_transmission, {"n": 1.33, "slope": 2.0, "distribution": "exponential"}),
    (models.smooth_diffuse, {"n": 1.5, "rho": 0.7}),
    (models.smooth_single, {"n": 1.5, "g": 0.3}),
    (models.smooth_single, {"n": 1.8, "g": -0.4}),
]
ROUGH = [
    (models.rough_diffuse, {"n": 1.5, "rho": 0.7, "slope": 0.3}),
    (models.rough_single, {"n": 1.5, "g": 0.3, "slope": 0.3}),
    (models.rough_single, {"n": 1.6, "g": 0.6, "slope": 1.5, "distribution": "exponential"}),
]


def _id(value):
    return getattr(value, "__name__", "")


def _exit_rotation(fn, phi):
    return normal_basis_rotation(phi, downward=fn is models.facet_transmission)


def _check_exit_rotation(fn, kw, theta_i, atol):
    at_zero = fn(theta_i, 0.0, 0.0, **kw)
    rotated = fn(theta_i, 0.0, PHI, **kw)
    predicted = _exit_rotation(fn, PHI) @ at_zero
    scale = at_zero[0, 0]
    np.testing.assert_allclose(rotated, predicted, rtol=0, atol=atol * scale)
    return rotated, at_zero, scale


@pytest.mark.parametrize(("fn", "kw"), CLOSED_FORM, ids=_id)
@pytest.mark.parametrize("theta_i", [0.0488, 0.3, 0.6, 0.0])
def test_normal_exit_rotates_with_phi_as_a_change_of_basis(fn, kw, theta_i):
    rotated, at_zero, scale = _check_exit_rotation(fn, kw, theta_i, 1e-12)
    # The rotation is not trivial: the polarization elements really change
    # (smooth_diffuse's rows 1 and 2 vanish along the normal, so it is
    # basis-free there).
    if fn is not models.smooth_diffuse:
        assert np.max(np.abs(rotated - at_zero)) > 0.05 * scale


@pytest.mark.parametrize(("fn", "kw"), ROUGH, ids=_id)
def test_rough_models_at_normal_exit_rotate_like_the_smooth_ones(fn, kw):
    """The rough models' exit facets turn rigidly with φs, so at θs = 0 only
    the quadrature's orientation changes (within its error, up to 4e-4 of
    M00 here); the basis rotation moves the polarization elements by up to
    M00."""
    for theta_i in (0.5, 0.0):
        rotated, at_zero, scale = _check_exit_rotation(fn, kw, theta_i, 1e-3)
        if fn is models.rough_single:
            assert np.max(np.abs(rotated - at_zero)) > 0.05 * scale


@pytest.mark.parametrize(("fn", "kw"), CLOSED_FORM + ROUGH, ids=_id)
def test_normal_exit_joins_its_neighbours_at_every_azimuth(fn, kw):
    """The limit along φs is the value at θs = 0 for every φs, not only at
    φs = 0: every Mueller element is continuous there."""
    for theta_i in (0.6, 0.0):
        a = fn(theta_i, 0.0, PHI, **kw)
        b = fn(theta_i, 1e-9, PHI, **kw)
        scale = a[..., 0, 0][..., None, None]
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-5 * np.max(scale))


@pytest.mark.parametrize(("fn", "kw"), CLOSED_FORM, ids=_id)
def test_normal_incidence_rotates_with_phi_as_a_change_of_basis(fn, kw):
    """At θi = 0 the scene is symmetric about the normal: turning φs turns
    the exit ray and its basis rigidly, while the incident basis stays at
    s = ŷ, so M(0, θs, φs) = M(0, θs, 0) · R(φs) with R the incident ray's
    change of basis."""
    ts = np.array([0.2, 0.5, 0.7, 0.0])
    at_zero = fn(0.0, ts[:, None], 0.0, **kw)
    rotated = fn(0.0, ts[:, None], PHI, **kw)
    predicted = at_zero @ normal_basis_rotation(PHI, downward=True)
    # At θs = 0 too the exit basis turns with φs (the limit along it).
    scale = at_zero[..., 0, 0][..., None, None]
    assert np.all(scale > 0.0)
    assert np.max(np.abs(rotated - predicted) / scale) < 1e-12
