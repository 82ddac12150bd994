"""Built-in examples: the paper's model curves, as plain data."""

from __future__ import annotations

import numpy as np

from . import figures, models

#: Fig. 2 (left): glossy white paint, totally diffuse scattering under a
#: smooth interface, n = 1.5 and rho = 0.93, measured at theta_i = 60 deg.
GLOSSY_WHITE = {"n": 1.5, "rho": 0.93}


def fig2_glossy_white(theta_s_deg=None, theta_i_deg=60.0):
    """In-plane f_r, η, P_c and P against θs (degrees, negative = the
    source's side) for the glossy white paint and 45° incident light, as the
    paper's solid curve in Fig. 2 (left).  Returns a dict of arrays."""
    if theta_s_deg is None:
        theta_s_deg = np.arange(-85.0, 86.0, 5.0)
    theta_s_deg = np.asarray(theta_s_deg, dtype=float)
    theta_s, phi_s = figures.in_plane(theta_s_deg)
    m = models.smooth_diffuse(np.radians(theta_i_deg), theta_s, phi_s, **GLOSSY_WHITE)
    q = models.polarization_parameters(m)
    return {"theta_s_deg": theta_s_deg, **q}
