"""Input validation shared by the models: every error names the parameter and
its allowed range (developers' guide: bad input gets a clear error)."""

from __future__ import annotations

import math

import numpy as np

DISTRIBUTIONS = ("gaussian", "exponential")


def index(n: float) -> float:
    """Binder refractive index: a finite real number > 0."""
    try:
        value = float(n)
    except (TypeError, ValueError):
        raise ValueError(f"n must be a finite real number > 0, got {n!r}") from None
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"n must be a finite real number > 0, got {n!r}")
    return value


def asymmetry(g: float) -> float:
    """Henyey-Greenstein asymmetry parameter: -1 < g < 1."""
    try:
        value = float(g)
    except (TypeError, ValueError):
        raise ValueError(f"g must be a real number with -1 < g < 1, got {g!r}") from None
    if not math.isfinite(value) or not -1.0 < value < 1.0:
        raise ValueError(f"g must be a real number with -1 < g < 1, got {g!r}")
    return value


def reflectance(rho: float, name: str = "rho") -> float:
    """A reflectance in [0, 1]."""
    try:
        value = float(rho)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number in [0, 1], got {rho!r}") from None
    if not math.isfinite(value) or not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be a real number in [0, 1], got {rho!r}")
    return value


def rms_slope(slope: float) -> float:
    """Total RMS slope: a finite real number >= 0."""
    try:
        value = float(slope)
    except (TypeError, ValueError):
        raise ValueError(f"slope must be a finite real number >= 0, got {slope!r}") from None
    if not math.isfinite(value) or value < 0.0:
        raise ValueError(f"slope must be a finite real number >= 0, got {slope!r}")
    return value


def distribution(name: str) -> str:
    """Slope distribution name, one of DISTRIBUTIONS."""
    if not isinstance(name, str) or name.lower() not in DISTRIBUTIONS:
        allowed = ", ".join(repr(d) for d in DISTRIBUTIONS)
        raise ValueError(f"distribution must be one of {allowed}, got {name!r}")
    return name.lower()


def positive_int(value: int, name: str, minimum: int = 1) -> int:
    """A whole number >= minimum."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be a whole number >= {minimum}, got {value!r}")
    return int(value)


def nodes(value, name: str = "nodes") -> tuple[int, int]:
    """A (radial, azimuthal) quadrature size: two whole numbers >= 1."""
    try:
        radial, azimuthal = value
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be two whole numbers >= 1, got {value!r}") from None
    return positive_int(radial, f"{name}[0]"), positive_int(azimuthal, f"{name}[1]")


def polar_angle(theta, name: str) -> np.ndarray:
    """Polar angle in radians, in [0, pi]; values >= pi/2 lie at or below the
    horizon and give zero BSDF."""
    arr = np.asarray(theta, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (radians in [0, pi]); got NaN or inf")
    if np.any(arr < 0.0) or np.any(arr > np.pi):
        raise ValueError(f"{name} must lie in [0, pi] radians (>= pi/2 gives zero)")
    return arr


def azimuth(phi, name: str) -> np.ndarray:
    """Azimuth in radians: any finite real number."""
    arr = np.asarray(phi, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (radians, any real value); got NaN or inf")
    return arr


def angles(theta_i, theta_s, phi_s, names=("theta_i", "theta_s", "phi_s"), broadcast=True):
    """Validate the three angle arrays of a BSDF evaluation and broadcast them
    (or, with ``broadcast=False``, only check that they broadcast)."""
    ti = polar_angle(theta_i, names[0])
    ts = polar_angle(theta_s, names[1])
    ps = azimuth(phi_s, names[2])
    try:
        np.broadcast_shapes(ti.shape, ts.shape, ps.shape)
    except ValueError:
        raise ValueError(
            f"{', '.join(names)} must broadcast to one shape, got {ti.shape}, {ts.shape}, {ps.shape}"
        ) from None
    return np.broadcast_arrays(ti, ts, ps) if broadcast else (ti, ts, ps)
