"""The Blender add-on on the pip bpy module (5.0.1): registration, the
material settings, presets, stale tracking and baking."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

import addon  # noqa: E402
import lut  # noqa: E402
from addon import api, jobs  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def registered():
    addon.register()
    yield
    addon.unregister()


@pytest.fixture
def material():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.data.materials.new("paint")


def test_register_and_unregister_cleanly():
    addon.unregister()
    assert not hasattr(bpy.types.Material, "paint_lut")
    assert not hasattr(bpy.types, "PAINTLUT_OT_bake")
    addon.register()
    assert hasattr(bpy.types.Material, "paint_lut")
    assert hasattr(bpy.ops.paint_lut, "bake")
    assert hasattr(bpy.types, "MATERIAL_PT_paint_lut") and hasattr(bpy.types, "NODE_PT_paint_lut")


def test_defaults_are_the_paint_defaults(material):
    settings = material.paint_lut
    assert settings.preset == "CUSTOM" and settings.stale
    assert api.paint_of(material) == lut.Paint()


def test_limits_follow_the_paint_limits():
    props = addon.properties.PaintLUTSettings.bl_rna.properties
    assert props["n"].hard_min == 1.0
    assert props["g"].hard_min > -1.0 and props["g"].hard_max < 1.0
    assert props["slope"].hard_min == 0.0 and props["slope"].hard_max == 3.0
    assert tuple(props["rho"].default_array) == pytest.approx((0.8, 0.8, 0.8)) and props["rho"].hard_max == 1.0
    assert props["facet"].hard_min == 0.0


def test_preset_fills_the_fields_and_bakes_the_spectral_paint(material):
    settings = material.paint_lut
    settings.stale = False
    settings.preset = "green_carc"
    carc = lut.preset("green_carc")
    assert settings.slope == pytest.approx(2.0) and settings.distribution == "EXPONENTIAL"
    assert settings.g == pytest.approx(0.3)
    np.testing.assert_allclose(tuple(settings.rho), np.clip(carc.rho.rgb(), 0, 1), rtol=1e-6)
    assert settings.stale
    assert api.paint_of(material) == carc  # the exact spectral paint, not its RGB


def test_editing_a_field_makes_the_paint_custom_and_stale(material):
    settings = material.paint_lut
    settings.preset = "glossy_white"
    settings.stale = False
    settings.g = 0.5
    assert settings.preset == "CUSTOM" and settings.stale
    paint = api.paint_of(material)
    assert paint.g == 0.5 and paint.rho == pytest.approx(tuple(settings.rho))


def test_bake_records_the_lut_and_clears_stale(material, tmp_path, monkeypatch):
    monkeypatch.setattr(api, "lut_directory", lambda: tmp_path)
    material.paint_lut.rho = (0.7, 0.2, 0.1)
    path = api.bake_material(material, resolution=(8, 6, 4))
    assert path.exists() and material.paint_lut.lut_path == str(path) and not material.paint_lut.stale
    assert lut.load_lut(path).paint == api.paint_of(material)
    material.paint_lut.slope = 0.2
    assert material.paint_lut.stale


def test_bake_operator_runs_headless(material, tmp_path, monkeypatch):
    monkeypatch.setattr(api, "lut_directory", lambda: tmp_path)
    material.paint_lut.preset = "glossy_white"
    with bpy.context.temp_override(material=material):
        assert bpy.ops.paint_lut.bake("EXEC_DEFAULT") == {"FINISHED"}
    assert not material.paint_lut.stale and material.paint_lut.lut_path.endswith(".exr")


def test_background_job_reports_progress_and_can_be_cancelled(tmp_path):
    job = jobs.BakeJob(lut.Paint(rho=0.5, single=0.3, slope=0.3), tmp_path, resolution=(8, 6, 4)).start()
    assert job.wait(60) and job.error is None and job.progress == 1.0 and job.path.exists()
    slow = jobs.BakeJob(lut.Paint(rho=0.4, single=0.3, slope=0.5), tmp_path, resolution=(96, 48, 24))
    slow.cancel()
    slow.start()
    assert slow.wait(60) and slow.error == "cancelled" and slow.path is None
    # Nothing half-written: only the first job's LUT and its two weights files.
    expected = [job.path, *(weights for _, weights in job.fits.values())]
    assert sorted(tmp_path.iterdir()) == sorted(expected)
    assert set(job.fits) == {"CYCLES", "EEVEE"}


def test_bake_wires_a_node_group(material, tmp_path, monkeypatch):
    monkeypatch.setattr(api, "lut_directory", lambda: tmp_path)
    material.paint_lut.preset = "glossy_white"
    api.bake_material(material, resolution=(8, 6, 4))
    tree = material.node_tree
    for target, suffix in (("CYCLES", ""), ("EEVEE", " Eevee")):
        # One output per engine, each fed by that engine's group.
        output = tree.get_output_node(target)
        assert output.target == target
        source = output.inputs["Surface"].links[0].from_node
        assert source.type == "GROUP" and source.node_tree.name == f"Paint LUT {material.name}{suffix}"
        image = next(nd.image for nd in source.node_tree.nodes if nd.type == "TEX_IMAGE")
        assert image.colorspace_settings.name == "Non-Color"
    # EEVEE renders Toon closures as Lambert: its group has none.
    eevee = addon.nodes.group_of(material, "EEVEE").node_tree
    assert not any(nd.type == "BSDF_TOON" for nd in eevee.nodes)
    assert any(nd.type == "BSDF_TOON" for nd in addon.nodes.group_of(material).node_tree.nodes)
    names = sorted(p.name.rsplit("-", 1)[0] for p in tmp_path.iterdir())
    assert names == ["paintfit", "paintfit-eevee", "paintlut"]
    # Rebaking rewires in place: still two outputs and two group nodes.
    material.paint_lut.stale = True
    api.bake_material(material, resolution=(8, 6, 4))
    assert sum(nd.type == "OUTPUT_MATERIAL" for nd in tree.nodes) == 2
    assert sum(nd.type == "GROUP" for nd in tree.nodes) == 2
    rough = bpy.data.materials.new("rough")
    rough.paint_lut.slope = 0.3
    api.bake_material(rough, resolution=(8, 6, 4))
    assert not rough.paint_lut.stale
    group = next(nd for nd in rough.node_tree.nodes if nd.type == "GROUP").node_tree
    assert any(nd.type == "BSDF_METALLIC" for nd in group.nodes)  # the facet lobe


def test_new_material_is_baked_and_wired(tmp_path, monkeypatch):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    monkeypatch.setattr(api, "lut_directory", lambda: tmp_path)
    paint = lut.Paint(rho=(0.6, 0.3, 0.2), single=0.1, g=0.2, slope=0.1)
    material = api.new_material("satin red", paint, resolution=(8, 6, 4))
    assert material.paint_lut.enabled and not material.paint_lut.stale
    assert api.paint_of(material) == paint
    assert any(nd.type == "GROUP" for nd in material.node_tree.nodes)
    carc = api.new_material("carc", lut.preset("green_carc"), resolution=(8, 6, 4))
    assert carc.paint_lut.preset == "green_carc"


def test_spectral_paints_are_stored_whole(tmp_path, monkeypatch):
    """A spectral paint that is not a preset survives on the material (and a
    save) exactly; the fields show its RGB; editing one makes it Custom RGB."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    monkeypatch.setattr(api, "lut_directory", lambda: tmp_path / "luts")
    paint = lut.Paint(n=(1.49, 0.0042), rho="ColorChecker N Ohta/blue", single=0.05)
    material = api.new_material("blue", paint, resolution=(8, 6, 4))
    material.use_fake_user = True
    settings = material.paint_lut
    assert settings.preset == "SPECTRAL" and not settings.stale
    assert api.paint_of(material) == paint
    assert settings.n == pytest.approx(float(paint.index_at(589.3)))
    assert tuple(settings.rho) == pytest.approx(tuple(paint.rho.rgb("Linear Rec.709")), abs=1e-6)
    blend = tmp_path / "blue.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    material = bpy.data.materials["blue"]
    assert api.paint_of(material) == paint
    material.paint_lut.g = 0.2
    assert material.paint_lut.preset == "CUSTOM" and material.paint_lut.stale
    assert not api.paint_of(material).spectral
    material.paint_lut.spectral_paint = "{broken"
    material.paint_lut.preset = "SPECTRAL"
    with pytest.raises(ValueError, match="not valid JSON"):
        api.paint_of(material)


def test_bake_scene_reports_baked_cached_unused(tmp_path, monkeypatch):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    monkeypatch.setattr(api, "lut_directory", lambda: tmp_path)
    scene = bpy.context.scene
    materials = [bpy.data.materials.new(name) for name in ("a", "b", "unused")]
    for i, material in enumerate(materials):
        material.paint_lut.enabled = True
        material.paint_lut.rho = (0.2 * (i + 1),) * 3
    for material in materials[:2]:
        mesh = bpy.data.meshes.new(material.name)
        mesh.materials.append(material)
        scene.collection.objects.link(bpy.data.objects.new(material.name, mesh))
    small = {"resolution": (8, 6, 4)}
    assert api.bake_scene(scene, **small) == {"a": "baked", "b": "baked", "unused": "unused"}
    assert api.bake_scene(scene, **small) == {"a": "cached", "b": "cached", "unused": "unused"}
    materials[1].paint_lut.g = 0.4
    assert api.bake_scene(scene, **small) == {"a": "cached", "b": "baked", "unused": "unused"}
    assert api.bake_scene(scene, force=True, **small)["a"] == "baked"


def test_saved_files_reference_luts_relatively(tmp_path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    material = api.new_material("paint", lut.Paint(rho=0.5), resolution=(8, 6, 4))
    assert material.paint_lut.lut_path.startswith("//paint_lut/paintlut-")
    group = next(nd for nd in material.node_tree.nodes if nd.type == "GROUP").node_tree
    image = next(nd.image for nd in group.nodes if nd.type == "TEX_IMAGE")
    assert image.filepath.startswith("//paint_lut/paintfit-")
    assert (tmp_path / "paint_lut").is_dir()
    assert "UNDO" in addon.operators.PAINTLUT_OT_bake.bl_options
