"""lut.Paint: the paper's incoherent combination, colour and spectra."""

import json

import numpy as np
import pytest

import lut
from lut import models
from lut.colour import management as cm

RNG = np.random.default_rng(3)
TI, TS, PS = RNG.uniform(0, 1.4, 200), RNG.uniform(0, 1.4, 200), RNG.uniform(-np.pi, np.pi, 200)


def test_rgb_paint_is_the_sum_of_the_models():
    """Each channel equals the models evaluated with that channel's values:
    the diffuse term's ρ factorization (Eq. 27) is exact."""
    for slope, dist in ((0.0, "gaussian"), (0.3, "gaussian"), (1.5, "exponential")):
        p = lut.Paint(
            n=1.4, rho=(0.9, 0.4, 0.05), single=(0.1, 0.3, 0.6), g=0.4, slope=slope, distribution=dist, facet=0.7
        )
        got = p.brdf(TI, TS, PS)
        for c in range(3):
            if slope:
                kw = {"n": 1.4, "slope": slope, "distribution": dist, "mueller": False}
                expect = 0.7 * models.facet_reflection(TI, TS, PS, **kw)
                expect += p.single[c] * models.rough_single(TI, TS, PS, g=0.4, **kw)
                expect += models.rough_diffuse(TI, TS, PS, rho=p.rho[c], **kw)
            else:
                expect = p.single[c] * models.smooth_single(TI, TS, PS, n=1.4, g=0.4, mueller=False)
                expect += models.smooth_diffuse(TI, TS, PS, n=1.4, rho=p.rho[c], mueller=False)
            np.testing.assert_allclose(got[:, c], expect, rtol=1e-12)


def test_specular_reflectance_is_the_smooth_interface_mirror():
    theta = np.radians([0.0, 30.0, 60.0, 89.0])
    rs, rp = models.fresnel.reflection_coefficients(np.cos(theta), 1.5)
    spec = lut.Paint(n=1.5, facet=0.5).specular_reflectance(theta)
    np.testing.assert_allclose(spec, 0.5 * 0.5 * (rs**2 + rp**2)[:, None] * np.ones(3), rtol=1e-12)
    assert np.all(lut.Paint(n=1.5, slope=0.2).specular_reflectance(theta) == 0)
    assert np.all(lut.Paint(n=1.5).specular_reflectance(np.pi / 2) == 0)


def test_flat_spectrum_equals_the_grey_rgb_paint():
    spectral = lut.Paint(rho=lut.Spectrum.flat(0.6), single=lut.Spectrum.flat(0.2), g=0.2, slope=0.3)
    grey = lut.Paint(rho=0.6, single=0.2, g=0.2, slope=0.3)
    assert spectral.spectral and not grey.spectral
    np.testing.assert_allclose(spectral.brdf(TI, TS, PS), grey.brdf(TI, TS, PS), rtol=1e-10)


def test_saturated_spectrum_differs_from_its_averaged_rgb():
    """The diffuse term is non-linear in ρ, so integrating per wavelength
    differs measurably from using the spectrum's RGB."""
    red = lut.Spectrum("ColorChecker N Ohta/red")
    spectral = lut.Paint(rho=red)
    averaged = lut.Paint(rho=tuple(np.clip(red.rgb(), 0, 1)))
    a, b = spectral.brdf(TI, TS, PS), averaged.brdf(TI, TS, PS)
    rel = np.abs(a - b) / b
    assert np.median(rel[:, 0]) > 0.01  # the red channel, where ρ varies most
    # ...while a flat spectrum and its RGB agree (previous test), so the
    # difference is the non-linearity, not the colour conversion.


def test_dispersion():
    red = lut.Spectrum("ColorChecker N Ohta/red")
    plain = lut.Paint(n=1.5, rho=red, slope=0.2)
    np.testing.assert_allclose(
        lut.Paint(n=(1.5, 0.0), rho=red, slope=0.2).brdf(TI, TS, PS), plain.brdf(TI, TS, PS), rtol=1e-12
    )
    disp = lut.Paint(n=(1.48, 0.006), rho=red)  # n(400 nm) = 1.5175, n(700 nm) = 1.4922
    assert disp.index_at(400) > disp.index_at(700)
    spec = disp.specular_reflectance(np.radians(45.0))
    low = lut.Paint(n=float(disp.index_at(780)), rho=red).specular_reflectance(np.radians(45.0))
    high = lut.Paint(n=float(disp.index_at(380)), rho=red).specular_reflectance(np.radians(45.0))
    assert np.all(low < spec) and np.all(spec < high)


def test_working_spaces():
    red = lut.Spectrum("ColorChecker N Ohta/red")
    rgb = {s: lut.Paint(rho=red, space=s).brdf(0.3, 0.5, 0.2) for s in cm.WORKING_SPACES}
    colour = cm._colour()
    converted = colour.RGB_to_RGB(
        rgb["Linear Rec.709"], "ITU-R BT.709", "ACEScg", chromatic_adaptation_transform="Bradford"
    )
    np.testing.assert_allclose(converted, rgb["ACEScg"], rtol=2e-3)
    grey = lut.Paint(rho=lut.Spectrum.flat(0.5))
    for s in cm.WORKING_SPACES:
        v = grey.converted(s).brdf(0.3, 0.5, 0.2)
        np.testing.assert_allclose(v, v[0], rtol=1e-12)
    moved = lut.Paint(rho=(0.8, 0.2, 0.1)).converted("Linear Rec.2020")
    assert moved.space == "Linear Rec.2020" and moved.rho[0] < 0.8


def test_presets_follow_the_paper():
    white, red, carc = (lut.preset(n) for n in ("glossy_white", "glossy_red", "green_carc"))
    assert white.n == 1.5 and white.slope == 0 and white.rho.at(632.8) == pytest.approx(0.93)
    assert carc.slope == 2.0 and carc.distribution == "exponential" and carc.g == 0.3
    assert carc.rho.at(632.8) == pytest.approx(0.05)
    assert red.has_single and red.facet == 1.0
    r, g, b = red.rho.rgb()
    assert r > 5 * g and r > 5 * b  # red
    r, g, b = carc.rho.rgb()
    assert g > r and g > b  # green


def test_paint_round_trips_through_json(tmp_path):
    csv = tmp_path / "s.csv"
    csv.write_text("wavelength,value\n400,0.1\n550,0.5\n700,0.9\n")
    data = {"n": 1.45, "rho": "ColorChecker N Ohta/blue", "single": {"spectrum": str(csv), "scale": 0.5}, "slope": 0.1}
    p = lut.Paint.from_dict(json.loads(json.dumps(data)))
    assert p.single.at(550) == pytest.approx(0.25)
    assert lut.Paint.from_dict(json.loads(json.dumps(p.to_dict()))) == p
    assert lut.Paint.from_dict({"rho": [0.1, 0.2, 0.3]}).rho == (0.1, 0.2, 0.3)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"n": -1}, "n must be"),
        ({"n": (1.5, float("nan"))}, "n as Cauchy coefficients"),
        ({"n": (1.5, 0.01)}, "needs a spectral paint"),
        ({"rho": 1.5}, r"rho must be a real number in \[0, 1\]"),
        ({"rho": (0.1, 0.2)}, "rho must be an RGB triple"),
        ({"single": "nonsense"}, "unknown spectrum"),
        ({"single": -0.1}, r"single must be a real number in \[0, 1\]"),
        ({"g": 1.0}, "g must be"),
        ({"slope": -1}, "slope must be"),
        ({"distribution": "cauchy"}, "distribution must be one of"),
        ({"facet": -1}, "facet must be a finite real number >= 0"),
        ({"space": "sRGB"}, "space must be one of 'Linear Rec.709'"),
        ({"rho": lut.Spectrum.flat(0.5), "single": (0.1, 0.2, 0.3)}, "single must be a Spectrum or a grey value"),
    ],
)
def test_bad_paint_parameters(kw, message):
    with pytest.raises(ValueError, match=message):
        lut.Paint(**kw)


def test_bad_paint_descriptions(tmp_path):
    with pytest.raises(ValueError, match="unknown paint field"):
        lut.Paint.from_dict({"colour": 1})
    with pytest.raises(ValueError, match="cannot read spectrum file"):
        lut.Paint.from_dict({"rho": str(tmp_path / "missing.csv")})
    with pytest.raises(ValueError, match=r"rho spectrum must lie in \[0, 1\]"):
        lut.Paint(rho=lut.Spectrum([400, 700], [0.5, 1.5]))
