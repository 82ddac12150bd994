"""The bundled paint library (addon/library.py, addon/assets/, made by
scripts/make_assets.py): the finishes' gloss, the library file's assets and
previews, the asset library's registration, and a material's first bake
after it is appended into an unsaved file."""

from __future__ import annotations

import importlib.util
import json
import pathlib

import pytest

import lut
from lut.paint import gloss, presets

ROOT = pathlib.Path(__file__).resolve().parents[1]
ASSETS = ROOT / "addon" / "assets"
BLEND = ASSETS / "paint_lut_library.blend"
CATALOGS = ASSETS / "blender_assets.cats.txt"


@pytest.mark.parametrize("name", list(presets.FINISHES))
def test_each_finish_reads_its_gloss_level_at_60_degrees(name):
    """The slope of each finish puts its modelled 60° specular gloss in
    its MPI level's range (what presets.FINISH_DATA claims)."""
    low, high = presets.GLOSS_RANGE[name]
    assert low <= gloss.specular_gloss(presets.finish(name), 60) <= high


def test_gloss_of_a_smooth_paint_is_its_fresnel_ratio_to_black_glass():
    """A smooth interface reads its mirror reflectance over the standard's
    (plus the little diffuse light inside the receptor)."""
    black = lut.Paint(n=1.567, rho=0.0, slope=0.0)
    assert gloss.specular_gloss(black, 60) == pytest.approx(100.0, abs=1e-9)
    glossy = lut.Paint(n=1.5, rho=0.0, slope=0.0)
    expected = 100 * gloss.fresnel_reflectance(1.0472, 1.5) / gloss.fresnel_reflectance(1.0472, 1.567)
    assert gloss.specular_gloss(glossy, 60) == pytest.approx(expected, rel=1e-3)


def test_library_is_the_papers_presets_then_the_finishes():
    assert list(presets.LIBRARY) == [*presets.PRESETS, *presets.FINISHES]
    assert set(presets.PRESETS) == {"glossy_white", "glossy_red", "green_carc"}  # the panel's enum is unchanged
    for name in presets.LIBRARY:
        paint = presets.library_paint(name)
        assert paint.n == 1.5 and paint.facet == 1.0
    with pytest.raises(ValueError, match="library paint must be one of"):
        presets.library_paint("lacquer")


def _make_assets():
    pytest.importorskip("bpy")
    spec = importlib.util.spec_from_file_location("make_assets", ROOT / "scripts" / "make_assets.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_make_assets_is_importable_and_lists_every_library_paint():
    make_assets = _make_assets()
    assert make_assets.paints() == list(presets.LIBRARY)
    in_catalogs = [name for names in make_assets.CATALOGS.values() for name in names]
    assert sorted(in_catalogs) == sorted(presets.LIBRARY)
    assert make_assets.library.LIBRARY_BLEND == BLEND


def _catalog_ids():
    ids = {}
    for line in CATALOGS.read_text().splitlines():
        if line and not line.startswith(("#", "VERSION")):
            uid, path, _ = line.split(":")
            ids[uid] = path
    return ids


def _load(names=None):
    """Append library materials (all, or those named) into the open file,
    as the Asset Browser's Append does."""
    import bpy

    with bpy.data.libraries.load(str(BLEND), link=False, assets_only=True) as (source, target):
        target.materials = [m for m in source.materials if names is None or m in names]
    return {m.name: m for m in target.materials}


def test_library_file_holds_one_asset_per_paint_with_a_preview(fresh_file):
    from addon import library

    make_assets = _make_assets()
    assert CATALOGS.read_text().splitlines()[6] == "VERSION 1"
    catalogs = _catalog_ids()
    materials = _load()
    assert sorted(materials) == sorted(make_assets.display_name(n) for n in presets.LIBRARY)
    for material in materials.values():
        name = material[library.PAINT]
        assert material.asset_data is not None
        assert catalogs[material.asset_data.catalog_id] == make_assets.catalog_of(name)
        preview = material.preview
        assert preview is not None and tuple(preview.image_size) == (128, 128)
        pixels = list(preview.image_pixels_float)
        assert max(pixels) > 0.2, f"{material.name}: empty preview"
        assert material.paint_lut.enabled and material[library.FIRST_USE]
        assert not material.paint_lut.lut_path  # nothing baked on the machine that made it
        from addon import api

        assert api.paint_of(material) == presets.library_paint(name, api.paint_of(material).space)


def test_library_file_is_written_by_the_oldest_supported_blender(fresh_file):
    """Blender 4.2 cannot read a file saved by Blender 5, so the library is
    written by the manifest's minimum version (make_assets.OLDEST)."""
    import tomllib

    import bpy

    make_assets = _make_assets()
    minimum = tomllib.loads((ROOT / "blender_manifest.toml").read_text())["blender_version_min"]
    assert tuple(int(v) for v in minimum.split(".")[:2]) == make_assets.OLDEST
    with bpy.data.libraries.load(str(BLEND), link=True) as (source, target):
        target.materials = source.materials[:1]
    library = next(lib for lib in bpy.data.libraries if pathlib.Path(lib.filepath).resolve() == BLEND.resolve())
    assert tuple(library.version[:2]) == make_assets.OLDEST


def test_registering_adds_the_asset_library_and_unregistering_removes_it(addon_registered):
    import bpy

    from addon import library

    bpy.ops.wm.read_factory_settings(use_empty=True)  # factory preferences: the entry is added again
    entry = library.find_library()
    assert entry is not None and pathlib.Path(entry.path).resolve() == ASSETS.resolve()
    assert entry.name == library.LIBRARY_NAME
    assert entry.import_method in library.IMPORT_METHODS
    library.register_library()  # registering again reuses the entry
    assert sum(library._same_folder(lib.path, ASSETS) for lib in library.asset_libraries()) == 1
    addon_registered.unregister()
    try:
        assert library.find_library() is None
        assert library._on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post
    finally:
        addon_registered.register()
    assert library.find_library() is not None


def _assert_working(material, directory):
    from addon import api, library, nodes

    assert library.FIRST_USE not in material and library.ERROR not in material
    settings = material.paint_lut
    assert settings.enabled and not settings.stale and settings.lut_path
    assert api.is_current(material, api.paint_of(material), directory=directory)
    for target in api.engine_targets():
        node = nodes.group_of(material, target)
        assert node is not None and nodes.is_paint_group(node.node_tree)
        outputs = [lk.to_node for lk in node.outputs["Shader"].links]
        assert any(o.type == "OUTPUT_MATERIAL" and o.target == target for o in outputs)


def test_an_appended_material_is_baked_on_first_use_in_an_unsaved_file(fresh_file, lut_dir):
    import bpy

    from addon import library

    assert not bpy.data.filepath
    material = _load({"Gloss"})["Gloss"]
    assert library.pending() == [material]
    bpy.ops.mesh.primitive_uv_sphere_add()
    bpy.context.object.data.materials.append(material)  # dropped on an object
    bpy.context.view_layer.update()  # the depsgraph handler schedules the bake
    assert bpy.app.timers.is_registered(library._on_timer)
    bpy.app.timers.unregister(library._on_timer)  # no event loop here: run it ourselves
    assert library.bake_pending(directory=lut_dir) == {"Gloss": "baked"}
    _assert_working(material, lut_dir)
    assert library.bake_pending(directory=lut_dir) == {}  # once only


def test_first_use_bakes_into_the_unsaved_files_folder(fresh_file):
    """With no directory given, an unsaved file's bake goes where the add-on
    puts it (api.lut_directory: the extension's user folder)."""
    from addon import api, library

    material = _load({"Glossy White"})["Glossy White"]
    assert library.bake_pending() == {"Glossy White": "baked"}
    _assert_working(material, api.lut_directory())


def test_a_failed_first_bake_is_recorded_not_raised(fresh_file, lut_dir):
    from addon import library

    material = _load({"Glossy White"})["Glossy White"]
    material.paint_lut.spectral_paint = json.dumps({"rho": {"spectrum": "no such spectrum"}})
    material.paint_lut.preset = "SPECTRAL"  # a stored spectral paint that is not valid: cannot be baked
    status = library.bake_pending(directory=lut_dir)
    assert status["Glossy White"].startswith("failed: ")
    assert library.FIRST_USE not in material and "spectrum 'no such spectrum'" in material[library.ERROR]
    assert library.pending() == []


def test_the_interactive_first_use_bakes_in_the_background(fresh_file):
    """What the timer does in a session: start a background bake (the
    interface does not wait), then wire its result once it is done."""
    from addon import api, library

    material = _load({"Glossy White"})["Glossy White"]
    assert library._on_timer() == library.POLL  # started, polling
    job = library._jobs["Glossy White"][0]
    assert job.wait(300) and not job.error
    assert library._on_timer() is None  # finished: nothing runs or waits
    _assert_working(material, api.lut_directory())


def test_a_saved_file_bakes_beside_itself_and_its_waiting_materials_are_found_on_load(fresh_file, tmp_path):
    """Open a saved file with a library material still waiting: the load
    handler schedules its bake, which goes to //paint_lut beside the file.
    Opening the library file itself schedules nothing (its bakes would land
    in the add-on's folder)."""
    import bpy

    from addon import library

    _load({"Glossy White"})
    blend = tmp_path / "scene.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    assert bpy.app.timers.is_registered(library._on_timer)
    bpy.app.timers.unregister(library._on_timer)
    material = bpy.data.materials["Glossy White"]
    assert library.bake_pending() == {"Glossy White": "baked"}
    assert material.paint_lut.lut_path.startswith("//paint_lut/")
    _assert_working(material, tmp_path / "paint_lut")

    bpy.ops.wm.open_mainfile(filepath=str(BLEND))
    assert library.pending() and not library.schedule()
    assert not bpy.app.timers.is_registered(library._on_timer)
    assert library.bake_pending() == {}
