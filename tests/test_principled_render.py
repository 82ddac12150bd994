"""The Principled fallback against Cycles (addon/scenes.py): the
model of lut.render.principled is Cycles' Principled BSDF, and the fitted fallback
of a material, as rendered, has the error the fit reports and beats the
Principled an artist would set up; the fallback leaves what Cycles and
EEVEE render of the paint unchanged and is what glTF and USD export."""

import json
import re

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

import lut  # noqa: E402
from addon.scenes import EEVEE, Oracle, oracle_errors, principled_params_material  # noqa: E402
from addon.scenes import principled as artists_principled  # noqa: E402
from lut.render import measure, principled  # noqa: E402

pytestmark = [pytest.mark.render, pytest.mark.cycles]

#: Light/view geometries (θl, θv, φ), grazing ones included.
GEOMETRIES = [(0.0, 0.1, 1.1), (0.5, 0.7, 1.2), (1.0, 0.35, 3.1), (0.26, 1.3, 0.4), (1.3, 1.3, 0.4), (0.8, 0.6, 0.1)]


@pytest.fixture(scope="module")
def oracle(addon_registered):
    return Oracle()


_principled_material = principled_params_material


@pytest.mark.parametrize(
    "params",
    [
        principled.PrincipledParams(base_color=(0.8, 0.4, 0.1), roughness=0.5, ior=1.5),
        principled.PrincipledParams(base_color=(0.2, 0.6, 0.9), roughness=0.2, ior=1.8),
        principled.PrincipledParams(base_color=(0.5, 0.5, 0.5), roughness=0.9, ior=1.3),
        principled.PrincipledParams(base_color=(0.9, 0.9, 0.9), roughness=0.0, ior=1.45),
        principled.PrincipledParams(
            base_color=(0.7, 0.3, 0.3), roughness=0.4, ior=1.5, coat_weight=0.7, coat_roughness=0.15, coat_ior=1.6
        ),
    ],
    ids=["orange", "blue-glossy", "grey-rough", "mirror", "coated"],
)
def test_model_is_cycles_principled(oracle, params):
    _principled_material(oracle, params)
    for geometry in GEOMETRIES:
        got = oracle.radiance(*geometry) / oracle.irradiance
        want = principled.radiance(params, *geometry)
        np.testing.assert_allclose(got, want, rtol=2e-3, atol=2e-3 * np.max(want), err_msg=str(geometry))


@pytest.mark.parametrize("name", ["glossy_red", "green_carc"])
def test_fitted_fallback_renders_with_its_error_and_beats_the_artist(oracle, name, lut_dir):
    from addon import api, export

    paint = lut.preset(name)
    material = oracle.material("paint")
    api.set_paint(material, paint)
    params, error = export.update_fallback(material, api.paint_of(material))
    # Not baked yet: the fallback is what renders (no engine outputs),
    # measured at the geometries its fit is measured on.
    points = measure.grid_points(principled.GRID, measure.MIRROR_EXCLUSION)
    rendered = oracle_errors(oracle, paint, points=points)[0]
    assert rendered == pytest.approx(error, rel=0.02, abs=5e-4)
    artist_material = artists_principled(oracle, paint)
    assert artist_material.node_tree.nodes["Principled BSDF"].distribution == "MULTI_GGX"
    artist = oracle_errors(oracle, paint, points=points)[0]
    print(f"{name}: fallback {rendered:.4f} (fit {error:.4f}), artist {artist:.4f}")
    assert rendered < 0.8 * artist


def test_fallback_changes_no_engine_render_and_is_exported(oracle, lut_dir, tmp_path):
    from addon import api, export

    material = oracle.material("paint")
    api.set_paint(material, lut.preset("glossy_white"))
    api.bake_material(material, directory=lut_dir, resolution=(8, 6, 4))  # a small LUT: only the wiring matters
    geometry = (0.5, 0.7, 1.2)
    before = {}
    for engine in ("CYCLES", EEVEE):
        oracle.scene.render.engine = engine
        before[engine] = oracle.radiance(*geometry)
    params, _ = export.update_fallback(material, api.paint_of(material))
    try:
        for engine in ("CYCLES", EEVEE):
            oracle.scene.render.engine = engine
            np.testing.assert_array_equal(oracle.radiance(*geometry), before[engine], err_msg=engine)
    finally:
        oracle.scene.render.engine = "CYCLES"
    outputs = {nd.name: nd for nd in material.node_tree.nodes if nd.type == "OUTPUT_MATERIAL"}
    assert outputs[export.OUTPUT].is_active_output and outputs[export.OUTPUT].target == "ALL"
    # Re-baking rewires the engine outputs; refreshing the fallback restores it.
    api.bake_material(material, directory=lut_dir, resolution=(8, 6, 4))  # a small LUT: only the wiring matters
    export.update_fallback(material, api.paint_of(material))
    assert [nd.target for nd in material.node_tree.nodes if nd.type == "OUTPUT_MATERIAL"].count("ALL") == 1

    path = tmp_path / "paint.gltf"
    bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLTF_SEPARATE")
    (exported,) = [m for m in json.loads(path.read_text())["materials"] if m["name"] == material.name]
    pbr = exported["pbrMetallicRoughness"]
    np.testing.assert_allclose(pbr["baseColorFactor"], [*params.base_color, 1.0], atol=1e-6)
    assert pbr["roughnessFactor"] == pytest.approx(params.roughness, abs=1e-6)
    assert pbr.get("metallicFactor", 1.0) == 0.0
    assert export.fallback_params(material)[0] == params

    # USD's exporter reads the same node (UsdPreviewSurface).
    usd = tmp_path / "paint.usda"
    assert bpy.ops.wm.usd_export(filepath=str(usd)) == {"FINISHED"}
    text = usd.read_text()
    colour = re.search(r"color3f inputs:diffuseColor = \(([^)]*)\)", text).group(1)
    np.testing.assert_allclose([float(v) for v in colour.split(",")], params.base_color, atol=1e-6)
    assert float(re.search(r"float inputs:roughness = (\S+)", text).group(1)) == pytest.approx(
        params.roughness, abs=1e-6
    )
    assert float(re.search(r"float inputs:ior = (\S+)", text).group(1)) == pytest.approx(params.ior, abs=1e-5)


def _exported_usd(path, name):
    """(diffuseColor, roughness) of material ``name`` in a .usda file."""
    text = path.read_text()
    block = text[text.index(f'def Material "{name}"') :]
    colour = re.search(r"color3f inputs:diffuseColor = \(([^)]*)\)", block).group(1)
    return [float(v) for v in colour.split(",")], float(re.search(r"float inputs:roughness = (\S+)", block).group(1))


@pytest.mark.parametrize("path", ["api", "panel"])
def test_a_new_material_exports_its_fallback_not_blenders_default(fresh_file, lut_dir, tmp_path, path):
    """A material as an artist makes it, through ``api.new_material`` or the
    panel's bake operator on a new material (Blender 5 gives it a default
    Principled BSDF that the paint's wiring leaves unlinked): glTF and USD
    export the paint's fitted fallback, not Blender's default grey."""
    from addon import api, export

    if path == "api":
        material = api.new_material("red_paint", lut.preset("glossy_red"), directory=lut_dir, resolution=(8, 6, 4))
    else:
        material = bpy.data.materials.new("red_paint")
        if material.node_tree is None:  # Blender 4.x: the panel's material has its default nodes
            material.use_nodes = True
        material.paint_lut.enabled = True
        material.paint_lut.preset = "glossy_red"
        bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
        with bpy.context.temp_override(material=material):
            assert bpy.ops.paint_lut.bake("EXEC_DEFAULT") == {"FINISHED"}
    params, _ = export.fallback_params(material)
    principled_nodes = [nd for nd in material.node_tree.nodes if nd.type == "BSDF_PRINCIPLED"]
    assert [nd.name for nd in principled_nodes] == [export.NODE]
    # A Principled BSDF an artist set aside (edited, unlinked) is kept.
    aside = material.node_tree.nodes.new("ShaderNodeBsdfPrincipled")
    aside.inputs["Base Color"].default_value = (0.1, 0.2, 0.3, 1.0)
    export.update_fallback(material, api.paint_of(material))
    assert aside.name in material.node_tree.nodes
    material.node_tree.nodes.remove(aside)
    mesh = bpy.data.meshes.new("plane")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    mesh.materials.append(material)
    bpy.context.scene.collection.objects.link(bpy.data.objects.new("plane", mesh))

    usd = tmp_path / "paint.usda"
    assert bpy.ops.wm.usd_export(filepath=str(usd)) == {"FINISHED"}
    colour, roughness = _exported_usd(usd, "red_paint")
    np.testing.assert_allclose(colour, params.base_color, atol=1e-6)
    assert roughness == pytest.approx(params.roughness, abs=1e-6)
    gltf = tmp_path / "paint.gltf"
    bpy.ops.export_scene.gltf(filepath=str(gltf), export_format="GLTF_SEPARATE")
    (exported,) = [m for m in json.loads(gltf.read_text())["materials"] if m["name"] == "red_paint"]
    np.testing.assert_allclose(exported["pbrMetallicRoughness"]["baseColorFactor"][:3], params.base_color, atol=1e-6)
