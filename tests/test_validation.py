"""Bad input raises ValueError naming the parameter and its allowed range."""

import numpy as np
import pytest

from lut import models
from lut.models import reference

GOOD = {
    models.facet_reflection: {"n": 1.5, "slope": 0.3, "distribution": "gaussian"},
    models.facet_transmission: {"n": 1.5, "slope": 0.3, "distribution": "gaussian"},
    models.smooth_diffuse: {"n": 1.5, "rho": 0.5},
    models.smooth_single: {"n": 1.5, "g": 0.3},
    models.rough_diffuse: {"n": 1.5, "rho": 0.5, "slope": 0.3, "distribution": "gaussian", "nodes": (4, 4)},
    models.rough_single: {"n": 1.5, "g": 0.3, "slope": 0.3, "distribution": "gaussian", "nodes": (4, 4)},
    reference.rough_single_random: {"n": 1.5, "g": 0.3, "slope": 0.3, "distribution": "gaussian", "pairs": 4},
}

BAD_PARAMS = [
    ("n", 0.0, "n must be a finite real number > 0"),
    ("n", -1.5, "n must be a finite real number > 0"),
    ("n", float("nan"), "n must be a finite real number > 0"),
    ("n", float("inf"), "n must be a finite real number > 0"),
    ("n", "glass", "n must be a finite real number > 0"),
    ("g", 1.0, "g must be a real number with -1 < g < 1"),
    ("g", -1.0, "g must be a real number with -1 < g < 1"),
    ("g", float("nan"), "g must be a real number with -1 < g < 1"),
    ("rho", -0.1, "rho must be a real number in [0, 1]"),
    ("rho", 1.01, "rho must be a real number in [0, 1]"),
    ("slope", -0.1, "slope must be a finite real number >= 0"),
    ("slope", float("inf"), "slope must be a finite real number >= 0"),
    ("distribution", "lorentzian", "distribution must be one of 'gaussian', 'exponential'"),
    ("distribution", None, "distribution must be one of 'gaussian', 'exponential'"),
    ("nodes", (0, 4), "nodes[0] must be a whole number >= 1"),
    ("nodes", (4, 2.5), "nodes[1] must be a whole number >= 1"),
    ("pairs", 0, "pairs must be a whole number >= 1"),
]


def _cases():
    for fn, good in GOOD.items():
        for name, value, message in BAD_PARAMS:
            if name in good:
                yield fn, {**good, name: value}, message


@pytest.mark.parametrize(("fn", "kw", "message"), list(_cases()), ids=lambda v: getattr(v, "__name__", None))
def test_bad_parameter_names_itself_and_its_range(fn, kw, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]").replace("(", r"\(")):
        fn(0.3, 0.4, 0.5, **kw)


@pytest.mark.parametrize("fn", list(GOOD), ids=lambda f: f.__name__)
@pytest.mark.parametrize(
    ("angles", "name"),
    [
        ((np.nan, 0.4, 0.5), "theta_i"),
        ((0.3, np.array([0.1, np.nan]), 0.5), "theta_"),
        ((0.3, 0.4, np.inf), "phi_"),
        ((-0.1, 0.4, 0.5), "theta_i"),
        ((0.3, 3.5, 0.5), "theta_"),
    ],
)
def test_bad_angles_name_the_angle(fn, angles, name):
    with pytest.raises(ValueError, match=name + r"\w* must"):
        fn(*angles, **GOOD[fn])


def test_facet_models_need_a_rough_surface():
    with pytest.raises(ValueError, match="slope must be > 0"):
        models.facet_reflection(0.3, 0.3, 0.0, n=1.5, slope=0.0)
    with pytest.raises(ValueError, match="slope must be > 0"):
        models.facet_transmission(0.3, 0.3, 0.0, n=1.5, slope=0.0)


def test_incompatible_angle_shapes_are_reported():
    with pytest.raises(ValueError):
        models.smooth_single(np.zeros(3), np.zeros(4), 0.0, n=1.5, g=0.0)


def test_polarization_parameters_reject_unphysical_stokes():
    m = models.smooth_diffuse(0.3, 0.4, 0.0, n=1.5, rho=0.5)
    with pytest.raises(ValueError, match="stokes_in"):
        models.polarization_parameters(m, stokes_in=(1.0, 1.0, 1.0, 0.0))
