"""Cycles (pip bpy 5.0.1) as a BRDF oracle, and the first closure the add-on's
node groups will use: the paper's Gaussian facet term is exactly Cycles'
Metallic BSDF (Beckmann, physical conductor, IOR n, extinction 0, roughness
sqrt(slope)), apart from Cycles' Smith shadowing near grazing."""

import math

import numpy as np
import pytest

pytest.importorskip("bpy")

from blender_oracle import Oracle, paints, relative_rms  # noqa: E402

from lut import closures, models  # noqa: E402


@pytest.fixture(scope="module")
def oracle():
    return Oracle()


def _surface(oracle, node_type):
    mat = oracle.material()
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.new(node_type)
    links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return bsdf


def test_lambert_is_rendered_exactly(oracle):
    diffuse = _surface(oracle, "ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.5, 0.25, 0.75, 1.0)
    for geometry in ((0.0, 0.3, 0.2), (0.7, 0.5, 2.0), (1.2, 0.9, -1.0)):
        np.testing.assert_allclose(oracle.brdf(*geometry), np.array([0.5, 0.25, 0.75]) / math.pi, rtol=1e-5)


@pytest.mark.parametrize(("n", "slope"), [(1.5, 0.2), (1.33, 0.05), (1.8, 0.25)])
def test_gaussian_facet_term_is_cycles_metallic_beckmann(oracle, n, slope):
    metal = _surface(oracle, "ShaderNodeBsdfMetallic")
    metal.distribution = "BECKMANN"
    metal.fresnel_type = "PHYSICAL_CONDUCTOR"
    metal.inputs["IOR"].default_value = (n, n, n)
    metal.inputs["Extinction"].default_value = (0.0, 0.0, 0.0)
    metal.inputs["Roughness"].default_value = math.sqrt(slope)
    # (θl, θv, φ) with φ = 0 the mirror direction, as φs in lut.models.
    geometries = [(0.5, 0.5, 0.0), (0.3, 0.6, 0.4), (0.8, 0.7, 0.3), (0.2, 0.25, 3.0), (1.0, 1.0, 0.1)]
    got = np.array([oracle.brdf(*g)[0] for g in geometries])
    ref = np.array([float(models.facet_reflection(*g, n=n, slope=slope, mueller=False)) for g in geometries])
    lit = ref > 1e-6 * ref.max()
    np.testing.assert_allclose(got[lit], ref[lit], rtol=1e-4)
    # Near grazing Cycles' Smith term G < 1 darkens the lobe a little; the
    # paper has no shadowing.
    grazing = oracle.brdf(1.3, 1.2, 0.0)[0] / float(
        models.facet_reflection(1.3, 1.2, 0.0, n=n, slope=slope, mueller=False)
    )
    assert 0.97 < grazing < 1.0


@pytest.mark.parametrize(
    "closure",
    [
        closures.Closure("diffuse_toon", 0.4, 0.3),
        closures.Closure("diffuse_toon", 1e-5, 1.0),
        closures.Closure("glossy_toon", 0.4, 0.3),
    ],
)
def test_toon_closures_match_cycles(oracle, closure):
    toon = _surface(oracle, "ShaderNodeBsdfToon")
    toon.component = "DIFFUSE" if closure.kind == "diffuse_toon" else "GLOSSY"
    toon.inputs["Size"].default_value = closure.size
    toon.inputs["Smooth"].default_value = closure.smooth
    toon.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)  # the node's default is 0.8 grey
    for geometry in ((0.1, 0.4, 0.3), (0.7, 0.4, 0.3), (0.9, 0.5, 0.0), (1.1, 0.8, 0.2), (0.5, 0.6, 2.5)):
        got = oracle.radiance(*geometry)[0] / oracle.irradiance
        assert got == pytest.approx(float(closure.evaluate(*geometry)), rel=1e-5, abs=1e-7)


#: The issue's targets: 2% for smooth paints, 5% for rough ones (satin, matte).
TARGETS = {"glossy white": 0.02, "smooth single": 0.02, "satin": 0.05, "matte": 0.05}


@pytest.mark.parametrize("name", list(TARGETS))
def test_paint_renders_within_target(oracle, name, tmp_path, monkeypatch):
    """The acceptance measure: rendered radiance against Paint.brdf · cos θl
    for θl, θv <= 75° away from the mirror direction, cos-weighted relative
    RMS <= 2% (smooth) or 5% (rough), through the add-on's own bake."""
    import addon
    from addon import api

    paint, target = paints()[name], TARGETS[name]
    addon.register()
    try:
        monkeypatch.setattr(api, "lut_directory", lambda: tmp_path)
        monkeypatch.setattr(api, "paint_of", lambda material: paint)
        material = oracle.material()
        api.bake_material(material, resolution=(8, 6, 4))
        assert relative_rms(oracle, paint) < target
    finally:
        addon.unregister()


@pytest.mark.parametrize(("n", "roughness"), [(1.5, 0.5), (1.33, 0.3), (1.6, 0.8)])
def test_ggx_closure_is_principled_with_a_black_base(oracle, n, roughness):
    """The 'ggx' closure (EEVEE's and Blender 4.2-4.5's facet lobe) against
    Cycles' Principled BSDF: black base, GGX, IOR n."""
    principled = _surface(oracle, "ShaderNodeBsdfPrincipled")
    principled.distribution = "GGX"
    principled.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    principled.inputs["IOR"].default_value = n
    principled.inputs["Roughness"].default_value = roughness
    closure = closures.Closure("ggx", ior=n, roughness=roughness)
    for geometry in ((0.5, 0.5, 0.0), (0.3, 0.6, 0.4), (0.8, 0.7, 0.3), (0.2, 0.25, 3.0), (1.1, 1.0, 0.1)):
        got = oracle.radiance(*geometry)[0] / oracle.irradiance
        assert got == pytest.approx(float(closure.evaluate(*geometry)), rel=2e-3)
