"""Jones-to-Mueller conversion and the paper's polarization quantities.

Jones matrices are arrays (..., 2, 2) with rows (s_out, p_out) and columns
(s_in, p_in); Stokes vectors are (I, Q, U, V) with Q = I_s - I_p.  The
conversion is the standard one of Bohren & Huffman (paper ref. 16), in the
element order SCATMECH uses (``MuellerMatrix(const JonesMatrix&)``).
"""

from __future__ import annotations

import numpy as np

#: The paper's measurement: 45° linearly polarized incident light.
STOKES_45 = np.array([1.0, 0.0, 1.0, 0.0])


def jones_to_mueller(jones: np.ndarray) -> np.ndarray:
    """Mueller matrix M(J) of a Jones matrix J (paper Eqs. 6, 14, 28, 42):
    returns (..., 4, 4)."""
    ss, ps = jones[..., 0, 0], jones[..., 0, 1]
    sp, pp = jones[..., 1, 0], jones[..., 1, 1]
    if np.iscomplexobj(jones):
        a_ss, a_pp, a_ps, a_sp = (np.abs(v) ** 2 for v in (ss, pp, ps, sp))
        c = np.conj
    else:
        a_ss, a_pp, a_ps, a_sp = ss * ss, pp * pp, ps * ps, sp * sp

        def c(v):
            return v

    ss_ps, pp_sp = ss * c(ps), pp * c(sp)
    ss_sp, pp_ps = ss * c(sp), pp * c(ps)
    pp_ss, sp_ps = pp * c(ss), sp * c(ps)
    m = np.empty(jones.shape[:-2] + (4, 4))
    m[..., 0, 0] = 0.5 * (a_pp + a_ss + a_ps + a_sp)
    m[..., 0, 1] = 0.5 * (a_ss - a_pp + a_sp - a_ps)
    m[..., 0, 2] = np.real(ss_ps + pp_sp)
    m[..., 0, 3] = np.imag(ss_ps - pp_sp)
    m[..., 1, 0] = 0.5 * (a_ss - a_pp - a_sp + a_ps)
    m[..., 1, 1] = 0.5 * (a_ss + a_pp - a_sp - a_ps)
    m[..., 1, 2] = np.real(ss_ps - pp_sp)
    m[..., 1, 3] = np.imag(ss_ps + pp_sp)
    m[..., 2, 0] = np.real(ss_sp + pp_ps)
    m[..., 2, 1] = np.real(ss_sp - pp_ps)
    m[..., 2, 2] = np.real(pp_ss + c(sp_ps))
    m[..., 2, 3] = np.imag(c(pp_ss) + sp_ps)
    m[..., 3, 0] = np.imag(c(ss_sp) + pp_ps)
    m[..., 3, 1] = np.imag(c(ss_sp) - pp_ps)
    m[..., 3, 2] = np.imag(pp_ss - c(sp_ps))
    m[..., 3, 3] = np.real(pp_ss - c(sp_ps))
    return m


def jones_product_m00(exit_coefficients, v, entry_coefficients):
    """M00 (the unpolarized element) of M(J) for the Jones product

        J = diag(b_s, b_p) · V · diag(a_s, a_p),

    a ray crossing one interface (amplitude coefficients a), projected by V
    and crossing another (b).  M00 = ½ Σ_jk |J_jk|² (the [0, 0] element of
    ``jones_to_mueller``; Bohren & Huffman), and with J_jk = b_j V_jk a_k

        M00 = ½ [b_s² (V_ss² a_s² + V_sp² a_p²) + b_p² (V_ps² a_s² + V_pp² a_p²)].

    This is the M00 of paper Eq. 13 (q_vol = diag(t_rs, t_rp) · V ·
    diag(t_is, t_ip), V the projection dyadic of Eq. 4 between the internal
    s/p vectors) and of its rough-interface counterpart, whose diagonal
    matrices act in the facets' local s/p bases: rotating into the global
    bases is orthogonal and leaves M00 unchanged.  Cheaper than building J
    and calling ``jones_to_mueller`` when only M00 is wanted.

    Parameters: ``exit_coefficients`` = (b_s, b_p); ``v`` = ((V_ss, V_sp),
    (V_ps, V_pp)), rows (s_out, p_out) and columns (s_in, p_in) as for every
    Jones matrix here; ``entry_coefficients`` = (a_s, a_p).  Real arrays that
    broadcast together; returns their broadcast shape."""
    b_s, b_p = exit_coefficients
    (v_ss, v_sp), (v_ps, v_pp) = v
    a_s, a_p = entry_coefficients
    a_s2, a_p2 = a_s * a_s, a_p * a_p
    return 0.5 * (
        b_s * b_s * (v_ss * v_ss * a_s2 + v_sp * v_sp * a_p2) + b_p * b_p * (v_ps * v_ps * a_s2 + v_pp * v_pp * a_p2)
    )


def polarization_parameters(mueller: np.ndarray, stokes_in=STOKES_45) -> dict:
    """The paper's plotted quantities (Sec. 3) for a Mueller BRDF and an
    incident Stokes vector (default 45° linear, the paper's measurement).

    Returns a dict of arrays:
      ``fr``  polarization-averaged BRDF M00 [sr⁻¹],
      ``eta`` principal angle of the scattered polarization, ½·atan2(U, Q),
              measured from s counter-clockwise looking into the beam [rad],
      ``pc``  degree of circular polarization V/I,
      ``p``   degree of polarization sqrt(Q² + U² + V²)/I.
    Where the scattered intensity is zero, eta, pc and p are NaN; where the
    light has no linear polarization (Q = U = 0), eta is NaN."""
    m = np.asarray(mueller, dtype=float)
    s_in = np.asarray(stokes_in, dtype=float)
    if s_in.shape != (4,) or s_in[0] <= 0 or np.sum(s_in[1:] ** 2) > s_in[0] ** 2 * (1 + 1e-12):
        raise ValueError("stokes_in must be a physical Stokes vector (I > 0, I² >= Q² + U² + V²)")
    s = m @ s_in
    i, q, u, v = s[..., 0], s[..., 1], s[..., 2], s[..., 3]
    lit = i > 0
    safe = np.where(lit, i, 1.0)
    nan = np.nan
    return {
        "fr": m[..., 0, 0],
        "eta": np.where(lit & ((q != 0) | (u != 0)), 0.5 * np.arctan2(u, q), nan),
        "pc": np.where(lit, v / safe, nan),
        "p": np.where(lit, np.sqrt(q * q + u * u + v * v) / safe, nan),
    }
