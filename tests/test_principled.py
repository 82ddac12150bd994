"""lut.render.principled: the model of Cycles' Principled BSDF and the fitted
fallback (numpy only; the model's agreement with Cycles is checked in
tests/test_principled_render.py)."""

import dataclasses

import numpy as np
import pytest

import lut
from lut.models import fresnel
from lut.render import principled


def test_table_at_zero_roughness_is_the_fresnel_factor():
    """A smooth layer's visible normal is the surface normal: s is the
    Fresnel interpolation factor (F(μ) - F0)/(1 - F0) itself."""
    mu = np.array([0.05, 0.3, 0.7, 1.0])
    rs, rp = fresnel.reflection_coefficients(mu, 1.5)
    f = 0.5 * (rs**2 + rp**2)
    f0 = 0.04
    np.testing.assert_allclose(principled._s_exact(1e-4, mu, 1.5), (f - f0) / (1 - f0), atol=1e-6)


def test_rough_layer_reflects_more_than_fresnel_at_normal_view():
    """Tilted visible normals see the Fresnel curve above F0: s > 0 at μ = 1
    for a rough layer, and s falls as the view rises (less grazing)."""
    s = principled._s_exact(0.8, np.array([0.2, 0.6, 1.0]), 1.5)
    assert s[2] > 0.001
    assert s[0] > s[1] > s[2]


def test_table_lookup_is_exact_at_the_nodes_and_linear_between():
    table = principled._table()
    n = float(principled._ior_of_z(4 / 15))
    assert principled.table_s(5 / 15, 9 / 15, n) == pytest.approx(table[4, 9, 5], abs=1e-6)
    mid = principled.table_s(5.5 / 15, 9 / 15, n)
    assert mid == pytest.approx(0.5 * (table[4, 9, 5] + table[4, 9, 6]), abs=1e-6)


def test_diffuse_is_what_the_specular_layer_leaves():
    """Base colour 1, no lobe off the mirror (roughness 0): radiance =
    (1 - albedo(θv))·cos θl/π, the albedo a smooth layer's Fresnel."""
    p = principled.PrincipledParams(base_color=(1, 1, 1), roughness=0.0, ior=1.5)
    theta_l, theta_v = 0.4, 0.9
    got = principled.radiance(p, theta_l, theta_v, 1.5)
    rs, rp = fresnel.reflection_coefficients(np.cos(theta_v), 1.5)
    want = (1 - 0.5 * (rs**2 + rp**2)) * np.cos(theta_l) / np.pi
    np.testing.assert_allclose(got, want, rtol=1e-3)  # the table's interpolation


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("roughness", 1.5, "roughness"),
        ("ior", 1.0, "ior"),
        ("coat_weight", -0.1, "coat_weight"),
        ("base_color", 2.0, "base_color"),
    ],
)
def test_bad_parameters_are_named(field, value, message):
    with pytest.raises(ValueError, match=message):
        principled.PrincipledParams(**{field: value})


def test_fit_recovers_a_principled_material():
    """A target that is itself a Principled BSDF is fitted to (near) zero
    error with its own parameters."""
    truth = principled.PrincipledParams(base_color=(0.6, 0.3, 0.1), roughness=0.45, ior=1.6)

    class Target:
        def brdf(self, tl, tv, ph):
            return principled.radiance(truth, tl, tv, ph) / np.cos(tl)[..., None]

    params, err = principled.fit_principled(Target(), coat=False)
    assert err < 1e-3
    assert params.roughness == pytest.approx(0.45, abs=0.01)
    assert params.ior == pytest.approx(1.6, abs=0.03)
    np.testing.assert_allclose(params.base_color, truth.base_color, atol=0.01)


def _artist(paint):
    """The artist's Principled (ρ, n, √slope) in this module's model."""
    rho = paint.rho.rgb(paint.space) if hasattr(paint.rho, "rgb") else np.asarray(paint.rho, dtype=float)
    return principled.PrincipledParams(
        base_color=tuple(np.clip(rho, 0, 1)), roughness=min(1.0, paint.slope**0.5), ior=float(paint.index_at(589.3))
    )


@pytest.mark.parametrize("name", list(lut.PRESETS))
def test_fit_beats_the_artists_principled_on_every_preset(name):
    paint = lut.preset(name)
    params, err = principled.fit_principled(paint)
    ref = principled.reference(paint)
    assert err == pytest.approx(principled.error(params, ref))
    assert err < principled.error(_artist(paint), ref)
    assert err < 0.20  # on the fidelity measure: glossy red 17.6%, green CARC 18.7%


def test_fit_from_a_lut_and_amplitudes_matches_the_paint(tmp_path):
    paint = lut.Paint(rho=(0.7, 0.5, 0.2), single=0.2, g=0.3, slope=0.3)
    table = lut.load_lut(lut.bake(paint, tmp_path, resolution=(24, 16, 12)))
    from_lut, err_lut = principled.fit_principled(table, table.amplitudes(paint))
    from_paint, err_paint = principled.fit_principled(paint)
    assert err_lut == pytest.approx(err_paint, abs=0.01)
    assert from_lut.roughness == pytest.approx(from_paint.roughness, abs=0.05)


def test_bad_sources_are_refused():
    with pytest.raises(TypeError, match="source"):
        principled.fit_principled("glossy_red")
    with pytest.raises(ValueError, match="amplitudes"):
        principled.fit_principled(lut.preset("glossy_red"), np.ones((3, 3)))
    with pytest.raises(ValueError, match="nothing to fit"):
        principled.fit_principled(lut.Paint(rho=0.0, facet=0.0))


def test_params_round_trip_through_a_dict():
    p = principled.PrincipledParams(base_color=(0.1, 0.2, 0.3), roughness=0.2, coat_weight=0.5)
    assert principled.PrincipledParams(**p.to_dict()) == p
    assert dataclasses.asdict(p)["coat_weight"] == 0.5
