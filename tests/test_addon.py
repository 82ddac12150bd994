"""The Blender add-on on the pip bpy module: registration, the material
settings, presets, live colours, stale tracking, baking paint types and the
node groups."""

import json
import os
import pathlib

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

import lut  # noqa: E402
from lut.render import bake as render_bake  # noqa: E402
from lut.render import fitting, measure  # noqa: E402

SMALL = {"resolution": (8, 6, 4)}


@pytest.fixture
def material(fresh_file):
    return bpy.data.materials.new("paint")


def _group_node(material, target="CYCLES"):
    from addon import nodes

    return nodes.group_of(material, target)


def _states(status):
    """{material name: state} of ``api.bake_materials``' statuses."""
    return {name: s.state for name, s in status.items()}


def _inputs(material, target="CYCLES"):
    node = _group_node(material, target)
    return {s.name: (tuple(s.default_value)[:3] if s.type == "RGBA" else s.default_value) for s in node.inputs}


def test_register_and_unregister_cleanly(addon_registered):
    addon_registered.unregister()
    assert not hasattr(bpy.types.Material, "paint_lut")
    assert not hasattr(bpy.types, "PAINTLUT_OT_bake")
    addon_registered.register()
    assert hasattr(bpy.types.Material, "paint_lut")
    assert hasattr(bpy.ops.paint_lut, "bake")
    assert hasattr(bpy.types, "MATERIAL_PT_paint_lut") and hasattr(bpy.types, "NODE_PT_paint_lut")


def test_defaults_are_the_paint_defaults(material):
    from addon import api

    settings = material.paint_lut
    assert settings.preset == "CUSTOM" and settings.stale
    assert api.paint_of(material) == lut.Paint()


#: The material settings that are not paint fields.
NOT_PAINT_FIELDS = {"rna_type", "name", "enabled", "preset", "lut_path", "stale", "internal_reflectance",
                    "diffuse_albedo", "seen", "fits", "spectral_paint", "osl", "osl_problem"}  # fmt: skip


def _float32(value):
    return float(np.float32(value))


def test_material_properties_are_the_schemas_fields_with_its_limits(addon_registered):
    """Every paint field the schema puts on a material is a property (and no
    other paint field is), with the schema's label, default, tooltip, hard
    and soft limits; the hard limits lie within what lut.Paint accepts."""
    from lut.paint.schema import PAINT_FIELDS

    props = addon_registered.properties.PaintLUTSettings.bl_rna.properties
    on_material = {name for name, spec in PAINT_FIELDS.items() if spec.on_material}
    assert on_material == {"n", "rho", "single", "g", "slope", "distribution", "facet"}
    assert {p.identifier for p in props} - NOT_PAINT_FIELDS == on_material
    for name in on_material:
        spec, prop = PAINT_FIELDS[name], props[name]
        assert prop.name == spec.label and prop.description, name
        if spec.kind == "choice":
            assert [item.identifier.lower() for item in prop.enum_items] == list(spec.choices)
            assert prop.default == spec.default.upper()
            continue
        hard = spec.material_range
        assert not hard.low_open and not hard.high_open and hard.bounded, name  # Blender's limits are closed
        assert (prop.hard_min, prop.hard_max) == (_float32(hard.low), _float32(hard.high)), name
        assert hard.low in spec.allowed and hard.high in spec.allowed, name
        soft_min, soft_max = spec.soft
        assert prop.soft_min == _float32(hard.low if soft_min is None else soft_min), name
        assert prop.soft_max == _float32(hard.high if soft_max is None else soft_max), name
        default = tuple(prop.default_array) if spec.kind == "colour" else prop.default
        assert default == pytest.approx(spec.default), name


def test_preset_fills_the_fields_with_the_rgb_that_renders_it_exactly(material):
    """A spectral preset's fields are the RGB pigment whose diffuse
    amplitude k(ρ) is the spectrally integrated one (so the colour inputs
    render the spectral paint exactly); bakes use the exact spectral paint."""
    from addon import api

    settings = material.paint_lut
    settings.stale = False
    settings.preset = "green_carc"
    carc = lut.preset("green_carc")
    assert settings.slope == pytest.approx(2.0) and settings.distribution == "EXPONENTIAL"
    assert settings.g == pytest.approx(0.3)
    rbar = carc.internal_reflectance()
    expected = lut.paint.pigment_of_amplitude(carc.amplitudes()[:, 2], rbar)
    np.testing.assert_allclose(tuple(settings.rho), expected, rtol=1e-6)
    assert not np.allclose(expected, carc.rho.rgb(), rtol=0.01)  # not the spectrum's RGB: ρ is not linear
    assert settings.stale  # another paint type
    assert api.paint_of(material) == carc  # the exact spectral paint, not its RGB


def test_type_fields_make_the_bake_stale_colours_do_not(material, lut_dir):
    from addon import api

    settings = material.paint_lut
    settings.preset = "glossy_white"
    api.bake_material(material, directory=lut_dir, **SMALL)
    assert not settings.stale
    settings.rho = (0.7, 0.2, 0.1)
    settings.single = (0.1, 0.0, 0.3)
    settings.facet = 0.6
    assert settings.preset == "CUSTOM" and not settings.stale  # colours are node inputs: no bake
    for target in ("CYCLES", "EEVEE"):  # and they reached both engines' groups at once
        values = _inputs(material, target)
        assert values["Pigment Color"] == pytest.approx((0.7, 0.2, 0.1))
        assert values["Single Scattering Color"] == pytest.approx((0.1, 0.0, 0.3))
        assert values["Surface Reflection"] == pytest.approx(0.6)
    settings.g = 0.5
    assert settings.stale
    paint = api.paint_of(material)
    assert paint.g == 0.5 and paint.rho == pytest.approx(tuple(settings.rho))


def test_every_colour_of_a_type_shares_one_bake_and_one_group(fresh_file, lut_dir):
    """Two materials of one paint type: the second bake computes nothing and
    both use the same node groups, each with its own colour inputs."""
    from addon import api

    a = api.new_material("car", lut.Paint(rho=(0.8, 0.1, 0.1), slope=0.2), directory=lut_dir, **SMALL)
    before = sorted(lut_dir.iterdir())
    b = bpy.data.materials.new("car Eevee")  # a name that once collided with the first's EEVEE group
    api.set_paint(b, lut.Paint(rho=(0.1, 0.1, 0.8), single=0.2, slope=0.2))
    result = api.bake_material(b, directory=lut_dir, **SMALL)
    assert result.computed == [] and sorted(lut_dir.iterdir()) == before
    for target in ("CYCLES", "EEVEE"):
        assert _group_node(a, target).node_tree == _group_node(b, target).node_tree
    assert _inputs(a)["Pigment Color"] == pytest.approx((0.8, 0.1, 0.1))
    assert _inputs(b)["Pigment Color"] == pytest.approx((0.1, 0.1, 0.8))
    status = api.bake_materials({a, b}, directory=lut_dir, **SMALL)
    assert _states(status) == {"car": "cached", "car Eevee": "cached"}
    assert status["car"].key == status["car Eevee"].key


def test_bake_records_the_lut_the_fits_and_their_errors(material, lut_dir):
    from addon import api

    material.paint_lut.rho = (0.7, 0.2, 0.1)
    result = api.bake_material(material, directory=lut_dir, **SMALL)
    assert result.lut_path.exists() and material.paint_lut.lut_path == str(result.lut_path)
    assert not material.paint_lut.stale
    assert lut.load_lut(result.lut_path).matches(api.paint_of(material))
    errors = api.fit_errors(material)
    assert set(errors) == {"CYCLES", "EEVEE"}
    paint = api.paint_of(material)
    for target, fit in errors.items():
        amps = result.lut.amplitudes(paint)
        assert isinstance(fit, api.FitError)
        assert fit.error == pytest.approx(result.fits[target].error(amps), rel=1e-6)
        assert fit.grazing == pytest.approx(result.fits[target].grazing_error(amps), rel=1e-6)
        assert (fit.target, fit.grazing_target) == measure.goals(target, smooth=True)
        assert fit.target == fitting.TARGET_ERROR[target]["smooth"]
        assert fit.missed == (fit.error > fit.target or fit.grazing > fit.grazing_target)
    assert all(result.errors(paint)[t] == pytest.approx(f.error, rel=1e-6) for t, f in errors.items())
    assert all(result.grazing_errors(paint)[t] == pytest.approx(f.grazing, rel=1e-6) for t, f in errors.items())
    material.paint_lut.single = (0.3, 0.3, 0.3)  # the error follows the colours' mix at once
    edited = api.fit_errors(material)
    amps = result.lut.amplitudes(api.paint_of(material))
    for target, fit in edited.items():
        assert fit.error == pytest.approx(result.fits[target].error(amps), rel=1e-6)
        assert fit.grazing == pytest.approx(result.fits[target].grazing_error(amps), rel=1e-6)
    # (Cycles' single-scatter and diffuse components miss by nearly the same
    # on this coarse LUT: its whole figure hardly moves, its grazing one does.)
    assert edited["CYCLES"].grazing != pytest.approx(errors["CYCLES"].grazing, rel=1e-3)
    assert edited["EEVEE"].error != pytest.approx(errors["EEVEE"].error, rel=1e-3)


def test_fit_errors_of_a_bake_stored_by_an_earlier_release(material, lut_dir):
    """A material baked by an earlier release stored its fits' matrices
    without the grazing band's and one goal: its errors still show, the
    grazing figure the whole one, the grazing goal the measure's."""
    from addon import api

    api.bake_material(material, directory=lut_dir, **SMALL)
    current = api.fit_errors(material)
    stored = json.loads(material.paint_lut.fits)
    for fit in stored.values():
        for key in ("grazing_residual", "grazing_reference", "goals"):
            del fit[key]
    material.paint_lut.fits = json.dumps(stored)
    errors = api.fit_errors(material)
    assert set(errors) == {"CYCLES", "EEVEE"}
    for target, fit in errors.items():
        assert fit.error == pytest.approx(current[target].error, rel=1e-12)
        assert fit.grazing == fit.error
        assert (fit.target, fit.grazing_target) == measure.goals(target, smooth=True)


def test_the_panel_and_the_status_show_both_figures(material, lut_dir):
    """The panel's line names the whole measure and the grazing band, each
    with its goal; a miss of either is a miss (the panel's warning icon,
    ``BakeStatus.misses``)."""
    from addon import api, panels

    fit = api.FitError(0.012, 0.02, 0.034, 0.04)
    assert panels.fit_error_text("CYCLES", fit) == "Cycles fit error 1.2% (target 2%), grazing light 3.4% (target 4%)"
    assert not fit.missed
    assert api.FitError(0.012, 0.02, 0.05, 0.04).missed and api.FitError(0.03, 0.02, 0.01, 0.04).missed
    status = api._status("baked", {"CYCLES": fit, "EEVEE": api.FitError(0.02, 0.03, 0.07, 0.06)}, "key")
    assert status.errors == {"CYCLES": 0.012, "EEVEE": 0.02}
    assert status.grazing == {"CYCLES": 0.034, "EEVEE": 0.07}
    assert status.misses == {"EEVEE": api.FitError(0.02, 0.03, 0.07, 0.06)}
    api.bake_material(material, directory=lut_dir, **SMALL)
    layout = _Layout()
    panels.draw_settings(layout, material)
    lines = [text for text, _ in layout.labels if "fit error" in text]
    assert len(lines) == 2 and all("grazing light" in text for text in lines)
    # Where EEVEE misses its goal the panel says why (and only there).
    misses = api.fit_errors(material)["EEVEE"].missed
    assert (panels.EEVEE_LIMIT in [text for text, _ in layout.labels]) == misses


def test_glossy_black_bakes_and_renders_only_its_mirror(material, lut_dir):
    """ρ = 0, no single scattering, smooth: the type still has its (unused)
    components, so the bake and the groups work; the colours are zero."""
    from addon import api

    api.set_paint(material, lut.Paint(rho=0.0))
    api.bake_material(material, directory=lut_dir, **SMALL)
    assert _inputs(material)["Pigment Color"] == pytest.approx((0.0, 0.0, 0.0))
    fallback = material.node_tree.nodes["Paint LUT Principled"]  # for export: a black dielectric mirror
    assert tuple(fallback.inputs["Base Color"].default_value)[:3] == (0.0, 0.0, 0.0)
    assert fallback.inputs["Roughness"].default_value == 0.0
    group = _group_node(material).node_tree
    assert any(nd.type == "BSDF_METALLIC" and nd.label.startswith("Mirror") for nd in group.nodes)


def test_bake_operator_runs_headless(material, tmp_path):
    """The operator bakes where the file says: next to the saved .blend."""
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    material.paint_lut.preset = "glossy_white"
    with bpy.context.temp_override(material=material):
        assert bpy.ops.paint_lut.bake("EXEC_DEFAULT") == {"FINISHED"}
    assert not material.paint_lut.stale and material.paint_lut.lut_path.endswith(".exr")
    assert (tmp_path / material.paint_lut.lut_path.removeprefix("//")).is_file()


def test_background_job_reports_progress_and_cancels_anywhere(tmp_path):
    """Progress runs over the LUT and every fit; a cancel in the fits (after
    the LUT) stops before any weights file is written."""
    from addon import jobs

    job = jobs.BakeJob(lut.Paint(rho=0.5, single=0.3, slope=0.3), tmp_path, **SMALL).start()
    assert job.wait(120) and job.error is None and job.progress == 1.0 and job.result.lut_path.exists()
    assert set(job.result.fits) == {"CYCLES", "EEVEE"}
    late = jobs.BakeJob(lut.Paint(rho=0.4, single=0.3, slope=0.5), tmp_path / "late", **SMALL)
    seen = []

    def progress(fraction, original=late._progress):
        seen.append(fraction)
        if fraction >= render_bake.LUT_SHARE:
            late.cancel()
        original(fraction)

    late._progress = progress
    late.start()
    assert late.wait(120) and late.error == "cancelled" and late.result is None
    assert max(seen) >= render_bake.LUT_SHARE
    assert not list((tmp_path / "late").glob("paintfit-*"))  # no fit written after the cancel
    slow = jobs.BakeJob(lut.Paint(rho=0.4, single=0.3, slope=0.5), tmp_path / "slow", resolution=(96, 48, 24))
    slow.cancel()
    slow.start()
    assert slow.wait(60) and slow.error == "cancelled"
    assert not (tmp_path / "slow").exists() or not list((tmp_path / "slow").iterdir())  # nothing half-written


def test_bake_wires_a_group_per_engine_with_colour_inputs(material, lut_dir):
    from addon import api, nodes

    material.paint_lut.preset = "glossy_white"
    api.bake_material(material, directory=lut_dir, **SMALL)
    tree = material.node_tree
    for target in ("CYCLES", "EEVEE"):
        output = tree.get_output_node(target)
        assert output.target == target
        source = output.inputs["Surface"].links[0].from_node
        assert source.type == "GROUP" and source.node_tree.name.startswith("Paint LUT n1.5 smooth")
        assert [s.name for s in source.inputs] == list(nodes.INPUTS)
        textures = [nd for nd in source.node_tree.nodes if nd.type == "TEX_IMAGE"]
        assert textures[0].image.colorspace_settings.name == "Non-Color"
        # Read by nearest column on the dense texture: EEVEE's mipmaps would
        # blend the rows of other closures into a Linear lookup.
        assert {nd.interpolation for nd in textures} == {"Closest"}
        assert textures[0].image.size[0] == fitting.TEXTURE_VIEWS
    eevee = _group_node(material, "EEVEE").node_tree
    assert not any(nd.type == "BSDF_TOON" for nd in eevee.nodes)  # EEVEE draws Toon closures as Lambert
    assert any(nd.type == "BSDF_TOON" for nd in _group_node(material).node_tree.nodes)
    names = sorted(p.name.rsplit("-", 1)[0] for p in lut_dir.iterdir())
    calibrated = "".join(map(str, api.eevee_calibration()))  # EEVEE fitted with this Blender's measured closures
    calibrated += "c"  # in the scene's default mode, Converged
    version = f"f{fitting.FIT_VERSION}"  # in the name: an older release's files are never overwritten
    # Cycles' OSL variant is baked beside its SVM fit (a material switches to it without a bake).
    assert names == [
        f"paintfit-cycles-{version}", f"paintfit-cyclesosl-{version}", f"paintfit-eevee{calibrated}-{version}",
        "paintlut",
    ]  # fmt: skip
    # A texture driving the pigment survives a rebake; still two outputs and two group nodes.
    texture = tree.nodes.new("ShaderNodeTexImage")
    tree.links.new(texture.outputs["Color"], _group_node(material).inputs["Pigment Color"])
    material.paint_lut.g = 0.3
    api.bake_material(material, directory=lut_dir, **SMALL)
    outputs = {nd.target for nd in tree.nodes if nd.type == "OUTPUT_MATERIAL" and nd.name != nodes.EXPORT_OUTPUT}
    assert outputs == {"CYCLES", "EEVEE"} and sum(nd.type == "OUTPUT_MATERIAL" for nd in tree.nodes) == 3
    export_output = tree.nodes[nodes.EXPORT_OUTPUT]  # the Principled fallback, for exporters
    assert export_output.target == "ALL" and export_output.is_active_output
    assert sum(nd.type == "GROUP" for nd in tree.nodes) == 2
    assert _group_node(material).inputs["Pigment Color"].links[0].from_node == texture
    rough = bpy.data.materials.new("rough")
    rough.paint_lut.slope = 0.3
    api.bake_material(rough, directory=lut_dir, **SMALL)
    assert not rough.paint_lut.stale
    group = _group_node(rough).node_tree
    assert any(nd.type == "BSDF_METALLIC" for nd in group.nodes)  # the facet lobe


def test_groups_are_laid_out_in_labelled_columns_without_overlap(material, lut_dir):
    """An artist who opens a group sees columns in frames (inputs, view
    angle, pigment, weights, colours, closures, sum): no two nodes overlap."""
    from addon import api, nodes

    api.set_paint(material, lut.Paint(rho=0.3, single=0.2, g=-0.4, slope=0.6, distribution="exponential"))
    api.bake_material(material, directory=lut_dir, **SMALL)
    for target in ("CYCLES", "EEVEE"):
        group = _group_node(material, target).node_tree
        frames = {nd.label for nd in group.nodes if nd.type == "FRAME"}
        assert {"Inputs", "View angle", "Weights per view", "Closures", "Sum of closures"} <= frames
        assert group.description
        boxes = []
        for nd in group.nodes:
            if nd.type in ("FRAME", "GROUP_OUTPUT"):
                continue
            x, y = nd.location
            boxes.append((nd.name, x, x + nd.width, y - nodes.estimated_height(nd), y))
        for i, (name, x0, x1, y0, y1) in enumerate(boxes):
            for other, u0, u1, v0, v1 in boxes[i + 1 :]:
                assert x1 <= u0 or u1 <= x0 or y1 <= v0 or v1 <= y0, (name, other)


def test_new_material_is_baked_and_wired(fresh_file, lut_dir):
    from addon import api

    paint = lut.Paint(rho=(0.6, 0.3, 0.2), single=0.1, g=0.2, slope=0.1)
    material = api.new_material("satin red", paint, directory=lut_dir, **SMALL)
    assert material.paint_lut.enabled and not material.paint_lut.stale
    assert api.paint_of(material) == paint
    assert _group_node(material) is not None
    carc = api.new_material("carc", lut.preset("green_carc"), directory=lut_dir, **SMALL)
    assert carc.paint_lut.preset == "green_carc"
    with pytest.raises(ValueError, match=r"n must be in \[1, 4\]"):
        api.new_material("clamped", lut.Paint(n=5.0), directory=lut_dir, **SMALL)
    assert "clamped" not in bpy.data.materials  # nothing left behind


def test_spectral_paints_are_stored_whole(fresh_file, tmp_path):
    """A spectral paint that is not a preset survives on the material (and a
    save) exactly; the fields show the RGB that renders it; editing one makes
    it Custom RGB."""
    from addon import api

    paint = lut.Paint(n=(1.49, 0.0042), rho="ColorChecker N Ohta/blue", single=0.05)
    material = api.new_material("blue", paint, directory=tmp_path / "luts", **SMALL)
    material.use_fake_user = True
    settings = material.paint_lut
    assert settings.preset == "SPECTRAL" and not settings.stale
    assert api.paint_of(material) == paint
    assert settings.n == pytest.approx(float(paint.index_at(589.3)))
    expected = render_bake.node_inputs(paint)["Pigment Color"]
    assert tuple(settings.rho) == pytest.approx(expected, abs=1e-6)
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


def test_bake_scene_reports_baked_cached_unused(fresh_file, lut_dir):
    from addon import api

    scene = bpy.context.scene
    materials = [bpy.data.materials.new(name) for name in ("a", "b", "unused")]
    for i, material in enumerate(materials):
        material.paint_lut.enabled = True
        material.paint_lut.rho = (0.2 * (i + 1),) * 3
    for material in materials[:2]:
        mesh = bpy.data.meshes.new(material.name)
        mesh.materials.append(material)
        scene.collection.objects.link(bpy.data.objects.new(material.name, mesh))
    small = {"directory": lut_dir, **SMALL}
    assert _states(api.bake_scene(scene, **small)) == {"a": "baked", "b": "baked", "unused": "unused"}
    assert _states(api.bake_scene(scene, **small)) == {"a": "cached", "b": "cached", "unused": "unused"}
    materials[1].paint_lut.g = 0.4
    status = api.bake_scene(scene, **small)
    assert _states(status) == {"a": "cached", "b": "baked", "unused": "unused"}
    assert status["a"].key != status["b"].key and set(status["b"].errors) == {"CYCLES", "EEVEE"}
    assert api.bake_scene(scene, force=True, **small)["a"].state == "baked"
    materials[0].paint_lut["n"] = -2.0  # as a script or a newer version might store it
    failed = api.bake_scene(scene, **small)["a"]
    assert failed.state == "failed" and "n must be" in failed.reason and str(failed) == f"failed: {failed.reason}"
    # Scripts of earlier releases compared the status with its state's name.
    assert failed == "failed" and failed != "baked" and status["a"] == "cached"
    assert status["a"] in {"cached", "baked"} and failed not in {"cached", "baked"}


def test_a_material_from_an_older_release_is_rebaked_not_trusted(material, lut_dir):
    """A group without colour inputs (the previous release's) is not
    current: batch and bake_scene rebake it, and the material is rewired."""
    from addon import api, nodes

    api.bake_material(material, directory=lut_dir, **SMALL)
    old = bpy.data.node_groups.new("Paint LUT paint", "ShaderNodeTree")
    old.interface.new_socket(name="Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    _group_node(material).node_tree = old
    assert not api.is_current(material, api.paint_of(material), directory=lut_dir, **SMALL)
    api.bake_materials({material}, directory=lut_dir, **SMALL)
    assert nodes.is_paint_group(_group_node(material).node_tree)


def test_saved_files_reference_luts_relatively(fresh_file, tmp_path):
    from addon import api, operators

    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    material = api.new_material("paint", lut.Paint(rho=0.5), **SMALL)
    assert material.paint_lut.lut_path.startswith("//paint_lut/paintlut-")
    image = next(nd.image for nd in _group_node(material).node_tree.nodes if nd.type == "TEX_IMAGE")
    assert image.filepath.startswith("//paint_lut/paintfit-")
    assert (tmp_path / "paint_lut").is_dir()
    assert "UNDO" in operators.PAINTLUT_OT_bake.bl_options
    # Cycles' OSL variant is stored as "OSL" where its ramps carry weight (a variant without them is the SVM fit).
    lut_file = pathlib.Path(bpy.path.abspath(material.paint_lut.lut_path))
    variant = fitting.read_fit(fitting.fit_path(lut_file, "CYCLES", api.nodes.EXACT_METALLIC, osl=True))
    expected = {"CYCLES", "EEVEE"} | ({"OSL"} if variant.draws_ramps else set())
    assert json.loads(material.paint_lut.fits).keys() == expected


def test_save_as_elsewhere_rebakes_what_points_at_the_old_folder(fresh_file, tmp_path):
    """Save As into another folder (paint_lut/ copied along): Blender remaps
    the images to the old folder; the bake is not current there until it
    is wired to the new folder's files."""
    import shutil

    from addon import api, nodes

    (tmp_path / "a").mkdir()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "a" / "scene.blend"))
    material = api.new_material("paint", lut.Paint(rho=0.5), **SMALL)
    material.use_fake_user = True
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "a" / "scene.blend"))
    shutil.copytree(tmp_path / "a" / "paint_lut", tmp_path / "b" / "paint_lut")
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "b" / "scene.blend"))
    material = bpy.data.materials["paint"]
    paint = api.paint_of(material)
    assert not api.is_current(material, paint, **SMALL)
    assert _states(api.bake_materials({material}, **SMALL)) == {"paint": "baked"}
    assert api.is_current(material, paint, **SMALL)
    weights = nodes.group_weights_path(_group_node(material).node_tree)
    assert weights.parent == (tmp_path / "b" / "paint_lut").resolve()


def test_a_foreign_lut_renamed_onto_a_materials_name_is_not_trusted(material, lut_dir):
    from addon import api

    api.bake_material(material, directory=lut_dir, **SMALL)
    mine = lut.lut_path(api.paint_of(material), lut_dir, **SMALL)
    other = lut.bake(lut.Paint(n=1.7), lut_dir / "other", **SMALL)
    other.replace(mine)
    assert not api.is_current(material, api.paint_of(material), directory=lut_dir, **SMALL)


def test_colour_as_seen_sets_the_pigment_that_shows_it(material, lut_dir):
    """The diffuse colour seen head-on is k(ρ)·a_D: setting it sets ρ (live),
    a white pigment's is the interface's transmittance (1 - R(0) when
    smooth), and the As Seen group computes the same ρ in nodes."""
    from addon import api

    api.bake_material(material, directory=lut_dir)  # a smooth type: the default resolution is quick
    settings = material.paint_lut
    assert settings.diffuse_albedo == pytest.approx(0.96, abs=2e-4)  # n = 1.5: 1 - R(0) = 0.96
    settings.seen = (0.5, 0.2, 0.05)
    assert tuple(settings.seen) == pytest.approx((0.5, 0.2, 0.05), abs=1e-5)
    rho = lut.paint.pigment_of_amplitude(
        np.array([0.5, 0.2, 0.05]) / settings.diffuse_albedo, settings.internal_reflectance
    )
    assert tuple(settings.rho) == pytest.approx(tuple(rho), abs=1e-5)
    assert not settings.stale and _inputs(material)["Pigment Color"] == pytest.approx(tuple(rho), abs=1e-5)
    assert rho[0] > 0.5  # the pigment is lighter than what is seen through the interface
    key = lut.load_lut(bpy.path.abspath(settings.lut_path)).key
    seen_group = bpy.data.node_groups[f"Paint LUT As Seen {key[:8]}"]
    assert {(s.name, s.in_out) for s in seen_group.interface.items_tree} == {
        ("Color (as seen)", "INPUT"),
        ("Pigment Color", "OUTPUT"),
    }


def test_a_seen_colour_beyond_white_pigment_is_capped_and_says_so(material, lut_dir):
    """ "Color as Seen" (1, 1, 1) cannot be shown through the binder: the
    pigment goes to white, the colour reads back a_D, and the panel's note
    says what it was capped at and why."""
    from addon import api, panels, properties

    api.bake_material(material, directory=lut_dir)
    settings = material.paint_lut
    settings.seen = (0.5, 0.2, 0.05)
    assert properties.seen_limit(settings) is None
    settings.seen = (1.0, 1.0, 1.0)
    assert tuple(settings.rho) == pytest.approx((1.0, 1.0, 1.0))
    assert tuple(settings.seen) == pytest.approx((settings.diffuse_albedo,) * 3, abs=1e-6)
    limit = properties.seen_limit(settings)
    assert limit == pytest.approx(0.96, abs=2e-4)
    assert panels.seen_limit_text(limit) == (
        "Seen colour capped at 0.96: a white pigment shows no more through the binder"
    )


def test_a_type_edited_during_a_background_bake_stays_stale(material, tmp_path):
    """The operator's background bake finishes after the artist changed the
    slope: the material is wired to what was baked but stays stale; a colour
    edited meanwhile reaches the groups."""
    from addon import api, jobs

    settings = material.paint_lut
    settings.slope = 0.2
    paint, started = api.paint_of(material), settings.type_key()
    job = jobs.BakeJob(paint, tmp_path, **SMALL).start()
    settings.slope = 0.4  # edited while the bake runs
    settings.rho = (0.2, 0.6, 0.1)
    assert job.wait(120) and job.error is None
    assert api.finish_background_bake(material, paint, job.result, started) is False
    assert settings.stale and _group_node(material) is not None
    assert _inputs(material)["Pigment Color"] == pytest.approx((0.2, 0.6, 0.1))
    settings.slope = 0.2  # back to the baked type: a fresh bake of it is current
    job = jobs.BakeJob(api.paint_of(material), tmp_path, **SMALL).start()
    assert job.wait(120) and api.finish_background_bake(
        material, api.paint_of(material), job.result, settings.type_key()
    )
    assert not settings.stale


def test_an_unsaved_file_bakes_into_a_folder_of_this_user(fresh_file):
    """Not a shared temporary folder that another user may own: the
    extension's user folder, or (outside an extension) a per-user one."""
    import getpass
    import tempfile

    from addon import api

    folder = api.lut_directory()
    assert folder.is_dir() and os.access(folder, os.W_OK)
    assert folder != pathlib.Path(tempfile.gettempdir()) / "paint_lut"
    assert getpass.getuser() in str(folder) or "extensions" in str(folder)


def test_the_export_fallback_follows_colour_edits(material, lut_dir):
    """After a bake the Principled fallback is fitted; a colour edit solves
    its base colour again at once (its shape waits for the next bake)."""
    from addon import api, export

    api.set_paint(material, lut.Paint(rho=(0.7, 0.3, 0.1), slope=0.2))
    api.bake_material(material, directory=lut_dir, **SMALL)
    before, _ = export.fallback_params(material)
    material.paint_lut.rho = (0.1, 0.3, 0.7)
    after, error = export.fallback_params(material)
    assert after.roughness == before.roughness and after.ior == before.ior
    assert after.base_color[2] > after.base_color[0] and before.base_color[0] > before.base_color[2]
    assert error is not None and error < 0.2  # a Principled BSDF is 15.8% off this paint on the fidelity measure


def test_a_paint_beyond_a_materials_limits_is_refused_naming_them(addon_registered):
    """check_paint_fits takes the panel fields' limits from the schema (equal
    to the properties', test above): just beyond one, the paint is refused."""
    from addon import validation
    from lut.paint.schema import PAINT_FIELDS

    for name, spec in PAINT_FIELDS.items():
        if not spec.on_material or spec.material is None:
            continue
        limits = spec.material
        value = limits.high + 0.005
        paint = lut.Paint(**{name: value})
        with pytest.raises(ValueError, match=f"^{name} must be {limits.text(name)}".replace("[", r"\[")):
            validation.check_paint_fits(paint, paint.space)
        validation.check_paint_fits(lut.Paint(**{name: limits.high}), paint.space)


class _Layout:
    """Records the properties a panel draws."""

    def __init__(self):
        self.props = []
        self.labels = []

    def prop(self, data, name, **_):
        assert name in data.bl_rna.properties, name
        self.props.append(name)

    def column(self, **_):
        return self

    row = column

    def label(self, text="", icon="NONE", **_):
        self.labels.append((text, icon))

    def operator(self, *_, **__):
        pass


def test_the_panel_shows_every_material_field_colours_first(material):
    from addon import panels, properties

    layout = _Layout()
    panels.draw_settings(layout, material)
    fields = [spec.name for spec in properties.MATERIAL_FIELDS]
    assert [p for p in layout.props if p in fields] == ["rho", "single", "facet", "n", "g", "slope", "distribution"]
    assert layout.props[:3] == ["enabled", "preset", "seen"]


def test_the_spectral_preset_is_offered_only_with_a_stored_spectrum(material, capfd):
    """With no spectral paint stored the menu has no Spectral; picking it
    over a stored paint that is not valid says so in one line (no
    traceback) and leaves the material to be baked, which then names the
    problem."""
    from addon import api, properties

    settings = material.paint_lut
    offered = [item[0] for item in properties._preset_items(settings, bpy.context)]
    assert "SPECTRAL" not in offered and "CUSTOM" in offered
    with pytest.raises(TypeError):
        settings.preset = "SPECTRAL"
    settings.spectral_paint = json.dumps({"rho": {"spectrum": "no such spectrum"}})
    offered = [item[0] for item in properties._preset_items(settings, bpy.context)]
    assert "SPECTRAL" in offered
    capfd.readouterr()
    settings.preset = "SPECTRAL"
    err = capfd.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1 and err.startswith(f"Paint LUT: {material.name}: ")
    assert settings.stale
    with pytest.raises(ValueError, match="spectrum"):
        api.paint_of(material)


def test_the_first_save_takes_an_unsaved_files_bakes_along(fresh_file, tmp_path):
    """Baked before the file had a path (into the user folder), a material's
    LUT and weights are copied beside the file on its first save, and the
    saved file points at them relative to itself: current in the panel, and
    found cached by the next batch (nothing rebaked)."""
    from addon import api, batch

    assert not bpy.data.filepath
    material = api.new_material("unsaved paint", lut.Paint(n=1.5, rho=(0.2, 0.5, 0.3)))  # smooth: quick
    assert pathlib.Path(material.paint_lut.lut_path).parent == api.user_lut_directory()
    mesh = bpy.data.meshes.new("tri")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    mesh.materials.append(material)
    bpy.context.scene.collection.objects.link(bpy.data.objects.new("tri", mesh))
    blend = tmp_path / "first.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))

    bpy.ops.wm.open_mainfile(filepath=str(blend))
    material = bpy.data.materials["unsaved paint"]
    settings = material.paint_lut
    assert settings.lut_path.startswith("//paint_lut/paintlut-") and not settings.stale
    assert (tmp_path / settings.lut_path.removeprefix("//")).is_file()
    weights = [image.filepath for image in bpy.data.images if image.filepath.endswith(".exr")]
    assert weights and all(path.startswith("//paint_lut/paintfit-") for path in weights)
    assert all((tmp_path / path.removeprefix("//")).is_file() for path in weights)
    entry = batch.bake_file(blend)
    assert entry["materials"]["unsaved paint"]["status"] == "cached", entry


def test_a_save_copy_of_an_unsaved_file_leaves_the_session_as_it_was(fresh_file, tmp_path):
    """Save Copy writes a complete file, but the session stays unsaved: its
    material keeps pointing at the bakes where they are."""
    from addon import api

    material = api.new_material("copied paint", lut.Paint(n=1.5, rho=(0.6, 0.5, 0.3)))
    material.use_fake_user = True  # saved though no object uses it
    before = material.paint_lut.lut_path
    images = {image.name: image.filepath for image in bpy.data.images}
    copy = tmp_path / "copy.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(copy), copy=True)
    assert not bpy.data.filepath and material.paint_lut.lut_path == before
    assert {image.name: image.filepath for image in bpy.data.images} == images
    assert api.is_current(material, api.paint_of(material), directory=api.user_lut_directory())
    bpy.ops.wm.open_mainfile(filepath=str(copy))
    assert bpy.data.materials["copied paint"].paint_lut.lut_path.startswith("//paint_lut/paintlut-")


def test_the_scenes_eevee_mode_picks_the_eevee_fit_and_the_panel_and_report_say_which(material, lut_dir):
    """Converged (the default) gives a sharp exponential paint, which
    EEVEE's three exact closures draw 20-25% off the model, its converged
    fit, with the samples it needs; switched to Exact, the material is no
    longer current, the panel says a bake applies it, and the bake computes
    the EEVEE fit alone."""
    from addon import api, batch, nodes, panels
    from lut import bench

    scene = bpy.context.scene
    assert scene.paint_lut.eevee_mode == "CONVERGED" == api.eevee_mode()
    paint = next(p for _, p in bench.random_paints(24) if p.distribution == "exponential" and 0 < p.slope < 0.15)
    api.set_paint(material, paint)
    api.bake_material(material, directory=lut_dir)
    assert nodes.group_of(material, "EEVEE").node_tree["paint_lut_eevee_mode"] == "CONVERGED"
    fit = api.fit_errors(material)["EEVEE"]
    assert fit.eevee_mode == "CONVERGED" and not fit.exact and 4 <= fit.samples <= 256
    layout = _Layout()
    panels.draw_settings(layout, material, scene)
    assert f"EEVEE: converged, about {fit.samples} samples (Render Samples in the scene)" in [
        t for t, _ in layout.labels
    ]
    assert "eevee_mode" in layout.props
    assert api.is_current(material, api.paint_of(material), directory=lut_dir)

    scene.paint_lut.eevee_mode = "EXACT"
    assert not api.is_current(material, api.paint_of(material), directory=lut_dir)
    layout = _Layout()
    panels.draw_settings(layout, material, scene)
    assert any(t.endswith("the scene asks Exact: bake to apply") for t, _ in layout.labels)
    result = api.bake_material(material, directory=lut_dir)
    assert result.computed == ["EEVEE"]  # the LUT and the Cycles fit were current
    fit = api.fit_errors(material)["EEVEE"]
    assert fit.eevee_mode == "EXACT" and fit.exact and fit.samples == 1
    assert fit.error > 0.15  # what the converged fit bought
    entry = batch._fit_entry(material)["fit"]
    assert entry["EEVEE"] | {"error": 0} == {
        "error": 0, "target": fit.target, "grazing": round(fit.grazing, 5), "grazing_target": fit.grazing_target,
        "mode": "EXACT", "exact_at_one_sample": True, "samples": 1,
    }  # fmt: skip
    assert "mode" not in entry["CYCLES"]
    assert api.is_current(material, api.paint_of(material), directory=lut_dir)


def test_the_osl_setting_switches_the_cycles_group_without_a_bake(material, lut_dir):
    """Off by default.  Switched on, a baked material's Cycles group becomes
    the OSL variant's (its SVM closures and one Script node of ramps) from
    the cached bake; the material is current, its errors name the variant,
    and the panel says what a scene without OSL draws.  Switched off, the SVM
    group is back."""
    from addon import api, nodes, panels

    api.set_paint(material, lut.Paint(rho=(0.02, 0.03, 0.02), slope=1.5, distribution="gaussian"))
    api.bake_material(material, directory=lut_dir, **SMALL)
    assert not material.paint_lut.osl and api.OSL_VARIANT not in api.fit_errors(material)
    svm = nodes.group_of(material, "CYCLES").node_tree
    assert not any(nd.type == "SCRIPT" for nd in svm.nodes)
    errors = api.fit_errors(material, variants=True)
    assert errors["CYCLES"].missed and errors[api.OSL_VARIANT].error < errors["CYCLES"].error
    layout = _Layout()
    panels.draw_settings(layout, material, bpy.context.scene)
    assert "osl" in layout.props  # offered: the SVM fit misses its goals
    assert any(t.startswith("With OSL, Cycles would render") for t, _ in layout.labels)

    material.paint_lut.osl = True  # rewired at once from the cached bake
    group = nodes.group_of(material, "CYCLES").node_tree
    scripts = [nd for nd in group.nodes if nd.type == "SCRIPT"]
    assert len(scripts) == 1 and scripts[0].bytecode and scripts[0].outputs["Ramps"].is_linked
    assert api.is_current(material, api.paint_of(material), directory=lut_dir, **SMALL)
    assert api.OSL_VARIANT in api.fit_errors(material)
    bpy.context.scene.render.engine = "CYCLES"
    bpy.context.scene.cycles.shading_system = False
    assert api.cycles_variant(material, bpy.context.scene) == "SVM"
    layout = _Layout()
    panels.draw_settings(layout, material, bpy.context.scene)
    assert any(t.startswith("Cycles renders the SVM closures here") for t, _ in layout.labels)
    bpy.context.scene.cycles.shading_system = True
    assert api.cycles_variant(material, bpy.context.scene) == "OSL"

    material.paint_lut.osl = False
    assert nodes.group_of(material, "CYCLES").node_tree == svm


def test_a_variant_whose_ramps_do_not_pay_renders_the_svm_group_and_says_so(material, lut_dir):
    """Where the variant has no ramps (a dispersive type, whose weights are
    per channel; or ramps that do not bring a type nearer its goals) it is
    the SVM fit: the bake stores no OSL figures (nothing to offer), and
    with the setting on the material keeps its SVM group, is current (no
    bake every time) and the panel says the ramps add nothing, not to turn
    OSL on."""
    from addon import api, nodes, panels

    paint = lut.Paint(n=(1.49, 0.006), rho="ColorChecker N Ohta/red")  # dispersive: the ramps are not fitted
    api.set_paint(material, paint)
    result = api.bake_material(material, directory=lut_dir)
    assert result.osl is not None and result.drawn_osl is None, "the case needs a type whose ramps are dropped"
    assert api.OSL_VARIANT not in api.fit_errors(material, variants=True)
    svm = nodes.group_of(material, "CYCLES").node_tree
    material.paint_lut.osl = True
    assert nodes.group_of(material, "CYCLES").node_tree == svm
    assert api.is_current(material, api.paint_of(material), directory=lut_dir)
    assert api.cycles_variant(material, bpy.context.scene) == "SVM"
    layout = _Layout()
    panels.draw_settings(layout, material, bpy.context.scene)
    assert any(t.startswith("The OSL ramps do not improve this paint type") for t, _ in layout.labels)
    assert not any("turn Open Shading Language on" in t for t, _ in layout.labels)


def test_a_blender_that_cannot_compile_the_ramps_keeps_the_svm_group_and_says_why(material, lut_dir, monkeypatch):
    """Turning the variant on where Cycles' OSL compiler fails (a build
    without OSL) is no error: the SVM group stays wired, no half-built
    group is left, the panel names the problem (and shows no OSL figures)
    and a bake of the file does not fail for it; the material is not
    current, so once the shader compiles the next bake builds the variant."""
    from addon import api, batch, nodes, osl, panels

    api.set_paint(material, lut.Paint(rho=(0.02, 0.03, 0.02), slope=1.5, distribution="gaussian"))
    api.bake_material(material, directory=lut_dir, **SMALL)
    svm = nodes.group_of(material, "CYCLES").node_tree
    groups = set(bpy.data.node_groups.keys())

    def no_compiler():
        raise RuntimeError("Cycles could not compile paint_lut_ramps.osl")

    monkeypatch.setattr(osl, "_compiled", no_compiler)  # the failure a Blender without OSL gives
    material.paint_lut.osl = True
    assert nodes.group_of(material, "CYCLES").node_tree == svm
    assert set(bpy.data.node_groups.keys()) == groups
    assert "could not compile" in material.paint_lut.osl_problem
    assert api.OSL_VARIANT not in api.fit_errors(material)  # the SVM closures render: their figures
    layout = _Layout()
    panels.draw_settings(layout, material, bpy.context.scene)
    assert any(t == material.paint_lut.osl_problem for t, _ in layout.labels)
    assert not any(t.startswith("Cycles OSL") for t, _ in layout.labels)  # it does not render here
    status = api.bake_materials({material}, force=True, directory=lut_dir, **SMALL)
    assert status[material.name].state == "baked" and api.OSL_VARIANT not in status[material.name].errors
    entry = batch._fit_entry(material)
    assert entry["cycles_variant"] == "SVM" and entry["osl_problem"] == material.paint_lut.osl_problem
    assert not api.is_current(material, api.paint_of(material), directory=lut_dir, **SMALL)  # a bake tries again

    monkeypatch.undo()  # a Blender that compiles it: the next bake of the file builds the variant
    status = api.bake_materials({material}, directory=lut_dir, **SMALL)
    assert status[material.name].state == "baked" and api.OSL_VARIANT in status[material.name].errors
    assert material.paint_lut.osl_problem == ""
    assert any(nd.type == "SCRIPT" for nd in nodes.group_of(material, "CYCLES").node_tree.nodes)
    assert api.is_current(material, api.paint_of(material), directory=lut_dir, **SMALL)
