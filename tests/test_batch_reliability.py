"""Batch baking finds every material a file renders, handles linked library
paint honestly, lets one bad material fail alone, keeps the .blend's
permissions and leaves no litter."""

import json
import math
import os
import pathlib
import stat
import struct
import subprocess
import sys

import pytest

bpy = pytest.importorskip("bpy")

import addon  # noqa: E402
import lut  # noqa: E402
from addon import api, batch  # noqa: E402
from lut.lutfiles import format as lutfile  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "batch_bake.py"


pytestmark = pytest.mark.usefixtures("addon_registered")


def run(*args, env=None):
    return subprocess.run(
        [sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True, env=env, cwd=ROOT
    )


def report_of(path):
    return json.loads(pathlib.Path(path).read_text())


def paint_material(name, rho=(0.2, 0.4, 0.6)):
    material = bpy.data.materials.new(name)
    material.paint_lut.enabled = True
    material.paint_lut.rho = rho
    return material


def triangle(name, material=None):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    if material is not None:
        mesh.materials.append(material)
    return bpy.data.objects.new(name, mesh)


def new_file():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


def save(path):
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return path


# ----------------------------------------------------------------------------- materials the depsgraph renders


def set_material_tree(material):
    tree = bpy.data.node_groups.new("set paint", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    group_in = tree.nodes.new("NodeGroupInput")
    group_out = tree.nodes.new("NodeGroupOutput")
    setter = tree.nodes.new("GeometryNodeSetMaterial")
    setter.inputs["Material"].default_value = material
    tree.links.new(group_in.outputs[0], setter.inputs["Geometry"])
    tree.links.new(setter.outputs["Geometry"], group_out.inputs[0])
    return tree


def make_instancing_blend(path):
    """'instanced' only through a collection instance, 'geonodes' only
    through a Geometry Nodes Set Material, 'spare' on a mesh no object
    shows."""
    scene = new_file()
    hidden = bpy.data.collections.new("props")  # not in the scene: rendered only through the instance
    hidden.objects.link(triangle("prop", paint_material("instanced")))
    empty = bpy.data.objects.new("props instance", None)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = hidden
    scene.collection.objects.link(empty)
    plain = triangle("plain")
    plain.modifiers.new("paint", "NODES").node_group = set_material_tree(paint_material("geonodes", (0.7, 0.2, 0.1)))
    scene.collection.objects.link(plain)
    spare = bpy.data.meshes.new("spare mesh")  # on a mesh no object shows: not rendered
    spare.materials.append(paint_material("spare"))
    spare.use_fake_user = True
    return save(path)


def test_materials_rendered_through_instances_and_geometry_nodes_are_baked(tmp_path):
    blend = make_instancing_blend(tmp_path / "instances.blend")
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    used = {m.name for m in api.used_materials(bpy.data.scenes)}
    assert {"instanced", "geonodes"} <= used and "spare" not in used

    report = tmp_path / "report.json"
    done = run(blend, "--report", report)
    assert done.returncode == 0, done.stderr
    assert "Read blend" not in done.stdout and "Read blend" in done.stderr  # stdout: the summary alone
    materials = report_of(report)[0]["materials"]
    assert {k: m["status"] for k, m in materials.items()} == {
        "instanced": "baked",
        "geonodes": "baked",
        "spare": "unused",
    }
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    for name in ("instanced", "geonodes"):
        assert addon.nodes.group_of(bpy.data.materials[name]) is not None


def test_materials_of_a_scene_blender_has_not_evaluated_are_found():
    """A second scene has no depsgraph in a background session: what its
    objects reach is still found (instances, Geometry Nodes, a background set)."""
    new_file()
    other = bpy.data.scenes.new("other")
    props = bpy.data.collections.new("props")
    props.objects.link(triangle("prop", paint_material("instanced")))
    empty = bpy.data.objects.new("props instance", None)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = props
    other.collection.objects.link(empty)
    plain = triangle("plain")
    tree = set_material_tree(paint_material("geonodes"))
    wrapper = bpy.data.node_groups.new("wrapper", "GeometryNodeTree")  # Set Material one group deeper
    wrapper.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    wrapper.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    inner = wrapper.nodes.new("GeometryNodeGroup")
    inner.node_tree = tree
    wrapper.links.new(wrapper.nodes.new("NodeGroupInput").outputs[0], inner.inputs[0])
    wrapper.links.new(inner.outputs[0], wrapper.nodes.new("NodeGroupOutput").inputs[0])
    plain.modifiers.new("paint", "NODES").node_group = wrapper
    other.collection.objects.link(plain)
    backdrop = bpy.data.scenes.new("backdrop")
    backdrop.collection.objects.link(triangle("wall", paint_material("backdrop")))
    other.background_set = backdrop
    paint_material("spare")
    assert other.view_layers[0].depsgraph is None
    assert {m.name for m in api.used_materials([other])} == {"instanced", "geonodes", "backdrop"}


# ----------------------------------------------------------------------------- linked library paint


def make_library(path):
    new_file()
    paint_material("asset paint", (0.8, 0.1, 0.1)).asset_mark()  # an asset: kept with a fake user, on no object
    return save(path)


def make_shot(path, library):
    scene = new_file()
    with bpy.data.libraries.load(str(library), link=True) as (_, linked):
        linked.materials = ["asset paint"]
    scene.collection.objects.link(triangle("wall", linked.materials[0]))
    local = paint_material("asset paint", (0.1, 0.1, 0.8))  # a local material of the same name
    scene.collection.objects.link(triangle("floor", local))
    return save(path)


def test_linked_paint_is_baked_in_its_library_and_reported_linked_elsewhere(tmp_path):
    library = make_library(tmp_path / "library.blend")
    shot = make_shot(tmp_path / "shot.blend", library)
    report = tmp_path / "report.json"
    linked_key = f"asset paint [{library.name}]"

    # Not baked in its library yet: reported, not faked, and the exit status says so.
    done = run(shot, "--report", report)
    assert done.returncode == 1, done.stderr
    entry = report_of(report)[0]
    linked = entry["materials"][linked_key]
    assert linked["status"] == "linked" and linked["baked"] is False
    assert linked["library"] == str(library.resolve()) and str(library.resolve()) in linked["reason"]
    assert entry["materials"]["asset paint"]["status"] == "baked"  # the local one of the same name
    assert "not baked in its library" in done.stdout

    # The library bakes its asset (used there as an asset), once.
    for expected in ("baked", "cached"):
        done = run(library, "--report", report)
        assert done.returncode == 0, done.stderr
        assert {n: m["status"] for n, m in report_of(report)[0]["materials"].items()} == {"asset paint": expected}

    done = run(shot, "--report", report)
    assert done.returncode == 0, done.stdout + done.stderr
    entry = report_of(report)[0]
    assert entry["status"] == "unchanged"
    assert entry["materials"][linked_key]["baked"] is True
    assert entry["materials"]["asset paint"]["status"] == "cached"


def test_a_library_of_materials_kept_by_fake_users_is_baked(tmp_path):
    """The classic library (before assets): paint materials no object uses,
    kept by a fake user for other files to link.  They are baked there, as
    assets are; a material nothing keeps is still unused."""
    new_file()
    kept = paint_material("kept paint")
    kept.use_fake_user = True
    paint_material("orphan paint")  # saved by nobody but this test's save
    library = save(tmp_path / "classic.blend")
    statuses = {n: m["status"] for n, m in batch.bake_file(library)["materials"].items()}
    assert statuses == {"kept paint": "baked"}  # the orphan is not even saved


def test_links_into_the_bundled_library_keep_their_fallback_and_it_is_never_written(tmp_path):
    """A paint linked from the add-on's own asset library is reported as
    keeping its fallback without failing the run, and the batch refuses to
    write that library (nor a paint_lut folder beside it)."""
    from addon import library

    scene = new_file()
    with bpy.data.libraries.load(str(library.LIBRARY_BLEND), link=True) as (_, linked):
        linked.materials = ["Satin"]
    scene.collection.objects.link(triangle("wall", linked.materials[0]))
    shot = save(tmp_path / "shot.blend")
    entry = batch.bake_file(shot)
    (satin,) = entry["materials"].values()
    assert satin["status"] == "linked" and satin["bundled"] is True and "Principled fallback" in satin["reason"]
    assert not batch.failed([entry]) and "reason" not in entry

    before = library.LIBRARY_BLEND.stat().st_mtime_ns
    listing = sorted(library.ASSETS.iterdir())
    entry = batch.bake_file(library.LIBRARY_BLEND, force=True)
    assert entry["status"] == "failed" and "the add-on's own asset library: never written" in entry["reason"]
    assert library.LIBRARY_BLEND.stat().st_mtime_ns == before and sorted(library.ASSETS.iterdir()) == listing

    # Another Blender version's install of the extension: known by its manifest.
    root = pathlib.Path(addon.__file__).resolve().parents[1]
    other = tmp_path / "4.2" / "extensions" / "user_default" / "paint_lut"
    (other / "assets").mkdir(parents=True)
    (other / "blender_manifest.toml").write_text((root / "blender_manifest.toml").read_text())
    (other / "assets" / library.LIBRARY_BLEND.name).write_bytes(library.LIBRARY_BLEND.read_bytes())
    assert batch.bundled(other / "assets" / library.LIBRARY_BLEND.name)
    (other / "blender_manifest.toml").write_text('id = "someone_else"\n')
    assert not batch.bundled(other / "assets" / library.LIBRARY_BLEND.name)


# ----------------------------------------------------------------------------- one bad material fails alone


def make_three(path):
    scene = new_file()
    for name in ("good", "broken", "spectral"):
        scene.collection.objects.link(triangle(name, paint_material(name, (0.3, 0.3, 0.3))))
    settings = bpy.data.materials["spectral"].paint_lut
    settings.spectral_paint = json.dumps({"rho": {"spectrum": "ColorChecker N Ohta/red", "scale": None}})
    settings["preset"] = 4  # SPECTRAL, as a file saved by a script or another version stores it
    return save(path)


def test_a_material_whose_bake_raises_anything_fails_alone(tmp_path, monkeypatch):
    blend = make_three(tmp_path / "three.blend")
    bake_material = api.bake_material

    def defect(material, **kwargs):
        if material.name == "broken":
            raise ZeroDivisionError("float division by zero")
        return bake_material(material, **kwargs)

    monkeypatch.setattr(api, "bake_material", defect)
    entry = batch.bake_file(blend)
    assert entry["status"] == "saved"
    assert entry["materials"]["good"]["status"] == "baked"
    assert entry["materials"]["broken"] == {"status": "failed", "reason": "ZeroDivisionError: float division by zero"}
    assert entry["materials"]["spectral"]["status"] == "failed"
    assert "spectrum scale must be a finite real number >= 0, got None" in entry["materials"]["spectral"]["reason"]
    assert entry["reason"] == "2 failed (broken, spectral)"  # by name, and nothing said of libraries
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    assert addon.nodes.group_of(bpy.data.materials["good"]) is not None  # its bake was saved


def test_a_damaged_lut_is_rebaked_with_the_numpy_reader(tmp_path, monkeypatch):
    monkeypatch.setattr(lutfile, "_oiio", lambda: None)  # as in Blender 4.2-4.3
    scene = new_file()
    scene.collection.objects.link(triangle("red", paint_material("red")))
    blend = save(tmp_path / "one.blend")
    assert {n: m["status"] for n, m in batch.bake_file(blend)["materials"].items()} == {"red": "baked"}
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    path = pathlib.Path(bpy.path.abspath(bpy.data.materials["red"].paint_lut.lut_path))
    height = math.prod(lutfile.read(path)[0].shape[:3])  # image rows: tiles x N_phi_d x N_theta_d
    data = bytearray(path.read_bytes())
    # The scanline offset table: its first entry points just past itself.
    at = next(p for p in range(len(data) - 8) if struct.unpack_from("<Q", data, p)[0] == p + 8 * height)
    data[at + 7] = 0x80  # one damaged byte: an offset beyond 2**63 (OverflowError in the reader)
    path.write_bytes(bytes(data))
    entry = batch.bake_file(blend)
    assert list(entry["materials"]) == ["red"] and entry["materials"]["red"]["status"] == "baked"
    assert entry["status"] == "saved"


# ----------------------------------------------------------------------------- permissions, litter, report path


@pytest.mark.parametrize("mode", [0o664, 0o600])
def test_saving_keeps_the_blend_permissions(tmp_path, mode):
    scene = new_file()
    scene.collection.objects.link(triangle("red", paint_material("red")))
    blend = save(tmp_path / "perm.blend")
    blend.chmod(mode)
    assert batch.bake_file(blend)["status"] == "saved"
    assert stat.S_IMODE(blend.stat().st_mode) == mode


def test_a_read_only_blend_is_reported_and_never_written(tmp_path):
    """A 0444 file in a writable folder stays as it is, --force or not: one
    that needs a save is reported failed, one whose bakes are current is
    unchanged (a read-only checkout of a baked shot)."""
    scene = new_file()
    scene.collection.objects.link(triangle("red", paint_material("red")))
    blend = save(tmp_path / "kept.blend")
    blend.chmod(0o444)
    before = blend.read_bytes()
    entry = batch.bake_file(blend, force=True)
    assert entry["status"] == "failed" and "kept.blend is read-only: kept as it is" in entry["reason"]
    red = entry["materials"]["red"]
    assert (red["status"], red["reason"]) == ("failed", "baked, but the file could not be saved")
    assert blend.read_bytes() == before and stat.S_IMODE(blend.stat().st_mode) == 0o444
    blend.chmod(0o644)
    assert batch.bake_file(blend)["status"] == "saved"
    blend.chmod(0o444)
    assert batch.bake_file(blend)["status"] == "unchanged"


def test_a_file_that_cannot_be_saved_lists_no_material_baked(tmp_path, monkeypatch):
    """When the .blend cannot be written, its bakes are not in it: the
    materials are failed, and the reason names the file, not the hidden
    temporary one."""
    scene = new_file()
    scene.collection.objects.link(triangle("red", paint_material("red")))
    blend = save(tmp_path / "shot.blend")

    def refuse(filepath):
        raise RuntimeError(f"Error: Cannot open file {filepath} for writing: No space left on device")

    (tmp_path / "a folder").mkdir()  # a space in the path: still named in full
    blend = save(tmp_path / "a folder" / "shot.blend")

    monkeypatch.setattr(batch, "_write_blend", refuse)
    entry = batch.bake_file(blend)
    assert entry["status"] == "failed" and ".partial" not in entry["reason"]
    assert entry["reason"].startswith(f"cannot save {blend}: Error: Cannot open file shot.blend for writing")
    assert entry["materials"]["red"]["status"] == "failed"
    assert entry["materials"]["red"]["reason"] == "baked, but the file could not be saved"


def test_a_file_that_cannot_be_read_is_not_said_to_have_no_paint_materials(tmp_path):
    missing = batch.bake_file(tmp_path / "missing.blend")
    text = batch.summary([missing])
    assert text.startswith(f"{tmp_path / 'missing.blend'}: failed: ") and "no paint materials" not in text


def test_parallel_jobs_leave_no_temporary_directory(tmp_path):
    files = []
    for i in range(2):
        scene = new_file()
        scene.collection.objects.link(triangle(f"m{i}", paint_material(f"m{i}")))
        files.append(save(tmp_path / f"{i}.blend"))
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    done = run(*files, "--jobs", "2", env={**os.environ, "TMPDIR": str(tmp)})
    assert done.returncode == 0, done.stderr
    assert list(tmp.iterdir()) == []


@pytest.mark.parametrize("where", ["directory", "read-only directory"])
def test_an_unwritable_report_fails_before_any_work(tmp_path, where):
    scene = new_file()
    scene.collection.objects.link(triangle("red", paint_material("red")))
    blend = save(tmp_path / "scene.blend")
    before = blend.read_bytes()
    if where == "directory":
        report = tmp_path / "reports"
        report.mkdir()
    else:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        report = locked / "report.json"
        if os.access(locked, os.W_OK):  # running as root: permissions do not apply
            pytest.skip("root can write anywhere")
    done = run(blend, "--report", report)
    assert done.returncode == 2
    assert "--report" in done.stderr and "Traceback" not in done.stderr
    assert blend.read_bytes() == before and not (tmp_path / "paint_lut").exists()


# ----------------------------------------------------------------------------- paints a material cannot hold


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"n": 0.8}, "n must be in [1, 4] on a material (the Paint LUT panel's limits), got 0.8"),
        ({"n": 5.0}, "n must be in [1, 4]"),
        ({"facet": 2.0}, "facet must be in [0, 1]"),
        ({"g": 0.995}, "g must be in [-0.99, 0.99]"),
        ({"slope": 3.5}, "slope must be in [0, 3]"),
    ],
)
def test_paints_beyond_the_panel_limits_are_refused(fields, message):
    from addon import validation

    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
        validation.check_paint_fits(lut.Paint(**fields), "Linear Rec.709")


def test_paints_within_the_limits_presets_and_spectral_paints_fit():
    from addon import validation

    for paint in (
        lut.Paint(n=1.0, g=-0.99, slope=3.0, facet=1.0, rho=(1.0, 0.0, 0.5)),
        lut.Paint(n=4.0, g=0.99),
        lut.preset("green_carc"),
        lut.Paint(n=0.8, rho="ColorChecker N Ohta/blue"),  # spectral: stored whole, never clamped
    ):
        validation.check_paint_fits(paint, "Linear Rec.709")
    # A saturated Rec.2020 red lies outside Rec.709: the material would clip it.
    with pytest.raises(ValueError, match="rho must be in \\[0, 1\\] per channel in the scene's working space"):
        validation.check_paint_fits(lut.Paint(rho=(1.0, 0.0, 0.0), space="Linear Rec.2020"), "Linear Rec.709")
    validation.check_paint_fits(lut.Paint(rho=(1.0, 0.0, 0.0), space="Linear Rec.709"), "Linear Rec.2020")


def test_the_limits_are_those_that_clamp_today():
    """What the check refuses is exactly what set_paint would change."""
    new_file()
    for paint in (lut.Paint(n=0.8), lut.Paint(n=5.0), lut.Paint(facet=2.0), lut.Paint(g=0.995)):
        material = bpy.data.materials.new("probe")
        addon.properties.set_fields(material.paint_lut, paint)  # what set_paint did before it checked
        assert api.paint_of(material) != paint  # clamped by the property
