"""A paint's whole Mueller matrix (``lut.Paint.mueller``) and the
polarization basis continuous over the hemisphere (``lut.polarized.basis``)
it can be referred to."""

from __future__ import annotations

import numpy as np
import pytest

from lut import bench, models
from lut.models import fresnel, geometry
from lut.polarized import basis

RANDOM = bench.random_paints(24)


def _geometries(rng, count):
    return (
        rng.uniform(0.0, np.radians(85.0), count),
        rng.uniform(0.0, np.radians(85.0), count),
        rng.uniform(-np.pi, np.pi, count),
    )


@pytest.mark.parametrize("index", [0, 1, 5, 9, 14, 22])
def test_a_paints_mueller_matrix_is_its_models_weighted_and_its_m00_is_its_brdf(index):
    """Per channel, the facet, single-scattering and diffuse Mueller
    matrices of ``lut.models`` times the paint's amplitudes; M00 equals
    ``brdf`` at random geometries of the randomised set."""
    paint = RANDOM[index][1]
    angles = _geometries(np.random.default_rng(index), 12)
    mueller = paint.mueller(*angles)
    assert mueller.shape == (12, 3, 4, 4)
    brdf = paint.brdf(*angles)
    np.testing.assert_allclose(mueller[..., 0, 0], brdf, rtol=1e-12, atol=1e-14 * brdf.max())
    amps = paint.amplitudes()
    n, g = paint.n, paint.g
    if paint.slope > 0:
        kw = {"n": n, "slope": paint.slope, "distribution": paint.distribution}
        terms = (
            models.facet_reflection(*angles, **kw),
            models.rough_single(*angles, g=g, **kw),
            models.rough_diffuse(*angles, rho=1.0, **kw),
        )
    else:
        terms = (
            np.zeros((12, 4, 4)),
            models.smooth_single(*angles, n=n, g=g),
            models.smooth_diffuse(*angles, n=n, rho=1.0),
        )
    expected = sum(t[:, None] * amps[None, :, c, None, None] for c, t in enumerate(terms))
    np.testing.assert_allclose(mueller, expected, rtol=1e-12, atol=1e-13 * brdf.max())
    # Not depolarizing alone: unpolarized light comes back partly polarized.
    assert np.abs(mueller[..., 1:, 0]).max() > 1e-3 * brdf.max()


def test_a_stokes_rotation_is_the_mueller_matrix_of_the_turned_jones_basis():
    """L(ψ) is M(R(ψ)) in the models' own Jones-to-Mueller convention, for
    R(ψ) the Jones components' change when s turns by ψ towards p."""
    for psi in np.linspace(-3.0, 3.0, 7):
        jones = np.array([[np.cos(psi), np.sin(psi)], [-np.sin(psi), np.cos(psi)]])
        np.testing.assert_allclose(basis.stokes_rotation(psi), models.jones_to_mueller(jones), atol=1e-15)
    # A half turn changes nothing; a quarter turn swaps s and p (Q and U change sign).
    np.testing.assert_allclose(basis.stokes_rotation(np.pi), np.eye(4), atol=1e-15)
    np.testing.assert_allclose(np.diag(basis.stokes_rotation(np.pi / 2)), [1, -1, -1, 1], atol=1e-15)


def test_the_transported_basis_is_orthonormal_and_smooth_through_the_poles():
    rng = np.random.default_rng(3)
    k = rng.normal(size=(500, 3))
    k /= np.linalg.norm(k, axis=-1, keepdims=True)
    s, p = basis.transported_basis(k)
    np.testing.assert_allclose(geometry.dot(s, k), 0.0, atol=1e-12)
    np.testing.assert_allclose(geometry.dot(s, s), 1.0, atol=1e-12)
    np.testing.assert_allclose(p, geometry.cross(k, s), atol=1e-15)
    # s is x̂ carried from the nearest pole: turned about (pole × k) by the angle between them (Rodrigues).
    pole = np.where(k[:, 2:] >= 0, 1.0, -1.0) * np.array([0.0, 0.0, 1.0])
    axis = geometry.cross(pole, k)
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = np.arccos(np.clip(geometry.dot(pole, k), -1.0, 1.0))[:, None]
    x = np.array([1.0, 0.0, 0.0])
    carried = x * np.cos(angle) + np.cross(axis, x) * np.sin(angle) + axis * (axis @ x)[:, None] * (1 - np.cos(angle))
    np.testing.assert_allclose(s, carried, atol=1e-12)
    # At either pole s is x̂, and a ray 1e-6 rad from it, at any azimuth, has
    # its s within 2e-6 of x̂: no azimuth-dependent limit.
    for z in (1.0, -1.0):
        for phi in np.linspace(-np.pi, np.pi, 9):
            t = 1e-6
            near = np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), z * np.cos(t)])
            assert np.abs(basis.transported_basis(near)[0] - [1.0, 0.0, 0.0]).max() < 2e-6
        np.testing.assert_allclose(basis.transported_basis(np.array([0.0, 0.0, z]))[0], [1.0, 0.0, 0.0])


def test_a_facet_reflection_referred_to_transported_bases_is_its_jones_matrix_built_in_them():
    """Independent of the change of basis: the facet term's Mueller matrix
    built from its Jones matrix written directly in the transported bases
    (the facet's local s = k_i × k_s, p = k × s on each ray, Fresnel's
    r_s, r_p between them), normalised by M00, against the SCATMECH-basis
    model turned into those bases; exit directions near the pole included."""
    rng = np.random.default_rng(7)
    ti, ts, ps = _geometries(rng, 40)
    ts[:8] = np.array([0.0, 1e-7, 1e-4, 0.01, 0.0, 1e-6, 0.02, 0.3])
    ti[:4] = 0.0
    n = 1.55
    model = models.facet_reflection(ti, ts, ps, n=n, slope=0.5, distribution="gaussian")
    turned = basis.mueller_in_transported_basis(model, ti, ts, ps)
    k_i = np.stack((np.sin(ti), np.zeros_like(ti), -np.cos(ti)), axis=-1)
    k_s = geometry.scattered(ts, ps)
    half = k_s - k_i
    half /= np.linalg.norm(half, axis=-1, keepdims=True)
    cos_iota = -geometry.dot(k_i, half)
    local_s = geometry.cross(k_i, k_s)
    norm = np.linalg.norm(local_s, axis=-1, keepdims=True)
    local_s = np.where(norm > 1e-12, local_s / np.where(norm > 1e-12, norm, 1.0), basis.transported_basis(k_i)[0])
    rs, rp = fresnel.reflection_coefficients(cos_iota, n)
    local_in = (local_s, geometry.cross(k_i, local_s))
    local_out = (local_s, geometry.cross(k_s, local_s))
    b_in, b_out = basis.transported_basis(k_i), basis.transported_basis(k_s)
    jones = np.zeros(ti.shape + (2, 2))
    for a in range(2):
        for b in range(2):
            jones[..., a, b] = geometry.dot(b_out[a], local_out[0]) * rs * geometry.dot(local_in[0], b_in[b])
            jones[..., a, b] += geometry.dot(b_out[a], local_out[1]) * rp * geometry.dot(local_in[1], b_in[b])
    built = models.jones_to_mueller(jones)
    built = built / built[..., :1, :1]
    np.testing.assert_allclose(turned / turned[..., :1, :1], built, atol=1e-6)


def test_a_paints_mueller_matrix_in_transported_bases_is_continuous_at_the_exit_pole():
    """On the randomised set: a view 1e-6 rad off the normal, at azimuths
    all round, gives one Mueller matrix in the transported bases (spread
    < 1e-4 of M00: the rough models' quadrature, up to 2e-5), where the s/p bases give matrices differing by up to
    tens of per cent of M00 (the limit along each azimuth)."""
    phi = np.radians([-170.0, -90.0, -20.0, 0.0, 45.0, 120.0])
    jumps = []
    for label, paint in RANDOM[::3]:
        for theta_i in (0.0, np.radians(50.0)):
            m = paint.mueller(theta_i, 1e-6, phi)
            t = basis.mueller_in_transported_basis(m, theta_i, 1e-6, phi)
            scale = m[..., 0, 0].max()
            assert np.ptp(t, axis=0).max() < 1e-4 * scale, label
            np.testing.assert_allclose(t[..., 0, 0], m[..., 0, 0], rtol=1e-14)
            jumps.append(np.ptp(m, axis=0).max() / scale)
    assert max(jumps) > 0.1


def test_a_mueller_matrix_of_the_wrong_shape_is_refused_by_name():
    with pytest.raises(ValueError, match="mueller must have shape angles"):
        basis.mueller_in_transported_basis(np.zeros((3, 4)), [0.1, 0.2, 0.3], 0.2, 0.0)
