"""Facet (geometric-optics) scattering by the exposed rough interface, in
reflection and in transmission (paper Sec. 2.4, Eqs. 29-43; SCATMECH's
``Facet_BRDF_Model``).  No shadowing or obscuration, as in the paper.

Both models are evaluated from closed forms in the angles: the facet normal
and slope (Eqs. 31-35), and the rotation between each ray's global s/p basis
and the facet's local one.  The local s vector is ∝ k_a × k_b (k_a, k_b the
two rays), so its components in the two global bases are simple dot products
(for reflection these are SCATMECH's a2 and a3 terms)."""

from __future__ import annotations

import numpy as np

from . import _validate, _vectorize, distributions, fresnel, geometry

#: Where |k_a × k_b| is below this the facet is met at normal incidence: its
#: local s vector is taken as the incoming ray's s (the result does not depend
#: on the choice there).
_NORMAL_EPS = 1e-12


def _rotations(ua, va, ub, vb, fallback_b):
    """Normalize the components (ua, va) of the local s vector in the incoming
    basis and (ub, vb) in the outgoing one; where they vanish use s_loc = s_a,
    whose outgoing components are ``fallback_b``.  Returns cos α, sin α,
    cos β, sin β."""
    norm = np.sqrt(ua * ua + va * va)
    ok = norm > _NORMAL_EPS
    inv = 1.0 / np.where(ok, norm, 1.0)
    fb_c, fb_s = fallback_b
    fb_norm = 1.0 / np.sqrt(fb_c * fb_c + fb_s * fb_s)
    return (
        np.where(ok, ua * inv, 1.0),
        np.where(ok, va * inv, 0.0),
        np.where(ok, ub * inv, fb_c * fb_norm),
        np.where(ok, vb * inv, fb_s * fb_norm),
    )


def _check(n, slope, distribution, name):
    n = _validate.index(n)
    slope = _validate.rms_slope(slope)
    distribution = _validate.distribution(distribution)
    if slope == 0.0:
        raise ValueError(f"slope must be > 0 for {name} (slope 0 is a delta: a mirror or a refracted beam)")
    return n, slope, distribution


def facet_reflection(theta_i, theta_s, phi_s, *, n, slope, distribution="gaussian", mueller=True):
    """Mueller BRDF [sr⁻¹] of specular reflection from facets of an isotropic
    rough surface (paper Sec. 2.4 and refs. 13, 19, 20):

        f = P(ζ) / (4 cos θi cos θs cos⁴θn) · M(J_r),

    with the facet normal n̂ ∝ k_s - k_i, ζ its slope (Eq. 35) and J_r the
    Fresnel reflection Jones matrix at the local angle ι (Eq. 33), rotated
    from the facet's s/p basis into the global ones.  The cos ι normalisation
    of Eq. 37 cancels against the Jacobian 1/(4 cos ι) of the mirror map.

    Parameters: angles in radians (broadcast); n binder index (> 0); slope the
    total RMS slope s (> 0); distribution 'gaussian' | 'exponential'.
    Returns shape broadcast(angles) + (4, 4), or M00 alone (shape of the angles)
    with ``mueller=False``.  Directions at or below the horizon give zero."""
    n, slope, distribution = _check(n, slope, distribution, "facet_reflection")
    angles = _validate.angles(theta_i, theta_s, phi_s, broadcast=False)

    def kernel(ci, si, up_i, cs, ss, up_s, cp, sp, want_mueller):
        # k_s - k_i = 2 cos ι n̂ (Eq. 35's facet); its transverse part gives the
        # slope without the cancellation of |k_s - k_i|² - (cos θi + cos θs)².
        hx, hy = ss * cp - si, ss * sp
        up = up_i & up_s
        zsum = np.where(up, ci + cs, 1.0)
        trans2 = hx * hx + hy * hy
        cos_iota = np.clip(0.5 * np.sqrt(trans2 + zsum * zsum), 0.0, 1.0)
        zeta2 = trans2 / (zsum * zsum)
        sec4 = (1.0 + zeta2) ** 2  # sec⁴θn, Eq. 38
        scale = np.where(
            up,
            distributions.pdf(np.sqrt(zeta2), slope, distribution) * sec4 / (4.0 * np.where(up, ci * cs, 1.0)),
            0.0,
        )
        rs, rp = fresnel.reflection_coefficients(cos_iota, n)
        if not want_mueller:
            return scale * 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)
        # Local s ∝ k_i × k_s; its components in the bases of k_i and k_s.
        # The outgoing basis has the azimuth φs even at θs = 0: the limit of
        # s = ẑ×k_s/|ẑ×k_s| along φs, as in SCATMECH (geometry module).
        cpb, spb = cp, sp
        rot = _rotations(
            -(ci * ss * cpb + si * cs),
            ss * spb,
            -(ci * ss + si * cs * cpb),
            si * spb,
            (cpb, -cs * spb),
        )
        return scale[:, None, None] * _vectorize.rotated_interface_mueller(rs, rp, *rot)

    return _vectorize.evaluate(kernel, angles, mueller)


def facet_transmission(theta_i, theta_t, phi_t, *, n, slope, distribution="gaussian", mueller=True):
    """Mueller BTDF [sr⁻¹] of refraction into the binder through the facets of
    an isotropic rough surface, paper Eq. 43:

        f = (dΩn/dΩt) · n cos ι_t sec⁴θn / (cos θt cos θi) · P(ζ) · M(J_facet),

    with n̂ from Eq. 31, ι_i and ι_t from Eqs. 33-34 (both must lie in
    [0, π/2], else zero), J_facet the Fresnel transmission Jones matrix at ι_i
    in the global s/p bases (Eqs. 40-41), and the Jacobian of Eq. 39 in the
    equivalent, better conditioned form dΩn/dΩt = n² cos ι_t / D² (D of Eq. 32;
    tests check the two agree).  θt is measured from the inward normal and
    φt = 0 is the regular refraction side.

    Parameters and return as for ``facet_reflection``.  At D = 0 (n = 1 in the
    forward direction, where the BTDF is a delta) the value is 0."""
    n, slope, distribution = _check(n, slope, distribution, "facet_transmission")
    angles = _validate.angles(theta_i, theta_t, phi_t, ("theta_i", "theta_t", "phi_t"), broadcast=False)

    def kernel(ci, si, up_i, ct, st, up_t, cp, sp, want_mueller):
        # v = k_i - n k_t (Eq. 31), D = |v| (Eq. 32), n̂ = ±v/D with n̂_z >= 0.
        vx, vy, vz = si - n * st * cp, -n * st * sp, n * ct - ci
        d2 = vx * vx + vy * vy + vz * vz
        ki_kt = si * st * cp + ci * ct
        sign = np.where(vz < 0.0, -1.0, 1.0)
        ok = up_i & up_t & (d2 > geometry.PARALLEL_EPS**2) & (vz != 0.0)
        d = np.sqrt(np.where(ok, d2, 1.0))
        cos_ii = -sign * (1.0 - n * ki_kt) / d  # -k_i · n̂ (Eq. 33)
        cos_it = -sign * (ki_kt - n) / d  # -k_t · n̂ (Eq. 34)
        ok &= (cos_ii >= 0.0) & (cos_it >= 0.0)
        vz_ok = np.where(ok, vz, 1.0)
        zeta2 = (vx * vx + vy * vy) / (vz_ok * vz_ok)
        sec4 = (1.0 + zeta2) ** 2
        jac = n * n * cos_it / np.where(ok, d2, 1.0)  # dΩn/dΩt, = Eq. 39
        density = distributions.pdf(np.sqrt(zeta2), slope, distribution) * sec4
        scale = np.where(ok, jac * n * cos_it * density / np.where(ok, ct * ci, 1.0), 0.0)
        t_s, t_p, _ = fresnel.transmission_coefficients(np.clip(cos_ii, 0.0, 1.0), n)
        if not want_mueller:
            return scale * 0.5 * (t_s * t_s + t_p * t_p)
        # Local s ∝ k_i × k_t; its components in the bases of k_i and k_t
        # (azimuth φt even at θt = 0, as in facet_reflection).
        cpb, spb = cp, sp
        rot = _rotations(
            si * ct - ci * st * cpb,
            st * spb,
            si * ct * cpb - ci * st,
            si * spb,
            (cpb, ct * spb),
        )
        return scale[:, None, None] * _vectorize.rotated_interface_mueller(t_s, t_p, *rot)

    return _vectorize.evaluate(kernel, angles, mueller)
