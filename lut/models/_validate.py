"""Input validation shared by the models: every error names the parameter and
its allowed range (developers' guide: bad input gets a clear error)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

DISTRIBUTIONS = ("gaussian", "exponential")


@dataclasses.dataclass(frozen=True)
class Range:
    """An interval of real numbers: ``low`` and ``high`` (None: unbounded),
    each end closed unless ``low_open`` / ``high_open``.  ``zero``, when
    given, also allows 0 and says what it means (e.g. "0 (smooth)")."""

    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    zero: str = ""

    def __contains__(self, value) -> bool:
        return self.contains(value)

    def contains(self, value: float, tolerance: float = 0.0) -> bool:
        """Whether the finite number ``value`` lies in the range widened by ``tolerance``."""
        if not math.isfinite(value):
            return False
        if self.zero and value == 0.0:
            return True
        if self.low is not None and (value <= self.low - tolerance if self.low_open else value < self.low - tolerance):
            return False
        return self.high is None or not (
            value >= self.high + tolerance if self.high_open else value > self.high + tolerance
        )

    @property
    def bounded(self) -> bool:
        return self.low is not None and self.high is not None

    def text(self, name: str = "x", noun: str = "") -> str:
        """The range in words, as error messages and help give it: "in [0, 1]",
        "with -1 < g < 1" (after a noun), "in (-1, 1)", "> 0", ">= 0"."""
        if self.bounded:
            if noun and self.low_open and self.high_open:
                interval = f"with {self.low:g} < {name} < {self.high:g}"
            else:
                left, right = "(" if self.low_open else "[", ")" if self.high_open else "]"
                interval = f"in {left}{self.low:g}, {self.high:g}{right}"
        elif self.low is not None:
            interval = f"{'>' if self.low_open else '>='} {self.low:g}"
        elif self.high is not None:
            interval = f"{'<' if self.high_open else '<='} {self.high:g}"
        else:
            interval = "finite"
        text = f"{noun} {interval}" if noun else interval
        return f"{self.zero} or {text}" if self.zero else text

    def interval(self) -> str:
        """The range in mathematical notation, for tables: "[0, 1]", "(−1, 1)", "≥ 0"."""
        low = "−∞" if self.low is None else f"{self.low:g}".replace("-", "−")
        high = "∞" if self.high is None else f"{self.high:g}".replace("-", "−")
        if self.bounded:
            text = f"{'(' if self.low_open else '['}{low}, {high}{')' if self.high_open else ']'}"
        elif self.low is not None:
            text = f"{'>' if self.low_open else '≥'} {low}"
        else:
            text = f"{'<' if self.high_open else '≤'} {high}"
        return f"{self.zero} or {text}" if self.zero else text


#: A real number: noun of the messages of ``check_range`` (a range open at
#: an end says "finite" too, as infinity would otherwise pass).
REAL = "a real number"


def range_error(value, name: str, allowed: Range, *, noun: str = REAL, context: str = "") -> ValueError:
    """The error for a ``value`` of parameter ``name`` outside ``allowed``:
    "<name> must be <noun> <range><context>, got <value>", e.g. "rho must be a
    real number in [0, 1], got 2.0", or without a noun "n must be in [1, 4]
    on a material ..., got 0.8"."""
    if noun == REAL and not allowed.bounded:
        noun = "a finite real number"
    return ValueError(f"{name} must be {allowed.text(name, noun)}{context}, got {value!r}")


def check_range(value, name: str, allowed: Range, *, noun: str = REAL, context: str = "", tolerance: float = 0.0):
    """``value`` as a float if it is a finite real number within ``allowed``
    (widened by ``tolerance``); else ValueError (``range_error``) naming the
    parameter and its range.  The one range check of lut and the add-on."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise range_error(value, name, allowed, noun=noun, context=context) from None
    if not allowed.contains(number, tolerance):
        raise range_error(value, name, allowed, noun=noun, context=context)
    return number


#: The models' parameter ranges (``lut.paint.schema`` gives a paint's fields these).
INDEX = Range(0.0, None, low_open=True)
ASYMMETRY = Range(-1.0, 1.0, low_open=True, high_open=True)
REFLECTANCE = Range(0.0, 1.0)
SLOPE = Range(0.0, None)


def index(n: float) -> float:
    """Binder refractive index: a finite real number > 0."""
    return check_range(n, "n", INDEX)


def asymmetry(g: float) -> float:
    """Henyey-Greenstein asymmetry parameter: -1 < g < 1."""
    return check_range(g, "g", ASYMMETRY)


def reflectance(rho: float, name: str = "rho") -> float:
    """A reflectance in [0, 1]."""
    return check_range(rho, name, REFLECTANCE)


def rms_slope(slope: float) -> float:
    """Total RMS slope: a finite real number >= 0."""
    return check_range(slope, "slope", SLOPE)


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
