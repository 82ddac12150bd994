"""Henyey-Greenstein phase function and its polarimetric form (paper Sec. 2.1)."""

from __future__ import annotations

import numpy as np


def henyey_greenstein(cos_theta, g: float):
    """Henyey-Greenstein phase function p(θ) [sr⁻¹], paper Eq. 2.

    θ is the angle between the incident and scattered propagation directions,
    so g > 0 peaks forward (g = <cos θ>).  The paper prints the denominator as
    (1 + 2g cos θ + g²); with θ measured between the two propagation directions
    that sign would make g the mean of -cos θ, contradicting the paper's own
    definition of g, so we use (1 - 2g cos θ + g²) as SCATMECH's
    ``Henyey_Greenstein_Phase_Function`` does."""
    c = np.asarray(cos_theta, dtype=float)
    d = 1.0 + g * g - 2.0 * g * c
    return (1.0 - g * g) / (4.0 * np.pi * d * np.sqrt(d))


def rayleigh_factor(cos_theta, g: float):
    """Scalar factor of the polarimetric HG phase function, paper Eq. 7:
    P = 2 p_HG(θ) / (1 + cos²θ) · M(J_vol), with J_vol the projection dyadic
    of Eq. 4 (diag(1, cos θ) in the σ/π basis of Eq. 3).  Its M00 is p_HG."""
    c = np.asarray(cos_theta, dtype=float)
    return 2.0 * henyey_greenstein(c, g) / (1.0 + c * c)
