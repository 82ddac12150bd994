"""Headless batch baking (addon.batch.main; scripts/batch_bake.py runs it): what is
used gets baked, the cache is honoured, broken inputs fail alone, and saving
is atomic."""

import json
import os
import pathlib
import subprocess
import sys

import pytest

bpy = pytest.importorskip("bpy")

import addon  # noqa: E402
from addon import batch  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "batch_bake.py"


pytestmark = pytest.mark.usefixtures("addon_registered")


def make_blend(path, used=("red", "blue"), unused=("spare",)):
    """A scene with one cube per used paint material and a paint material
    on a mesh no object shows (a material kept by a fake user alone is a
    library's, and bakes)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for i, name in enumerate((*used, *unused)):
        material = bpy.data.materials.new(name)
        material.paint_lut.enabled = True
        material.paint_lut.rho = (0.1 + 0.2 * i, 0.3, 0.5)
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
        mesh.materials.append(material)
        if name in used:
            scene.collection.objects.link(bpy.data.objects.new(name, mesh))
        else:
            mesh.use_fake_user = True  # kept in the file, shown by no object
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return path


def edit_blend(path, material, **fields):
    bpy.ops.wm.open_mainfile(filepath=str(path))
    for key, value in fields.items():
        setattr(bpy.data.materials[material].paint_lut, key, value)
    bpy.ops.wm.save_as_mainfile(filepath=str(path))


def run(*args, cwd=None):
    done = subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True, cwd=cwd)
    return done


def report_of(path):
    return json.loads(pathlib.Path(path).read_text())


def statuses(report_path, index=0):
    entry = json.loads(pathlib.Path(report_path).read_text())[index]
    return entry, {name: m["status"] for name, m in entry["materials"].items()}


def test_bake_cache_edit_and_corruption(tmp_path):
    blend = make_blend(tmp_path / "scene.blend")
    report = tmp_path / "report.json"

    done = run(blend, "--report", report)
    assert done.returncode == 0, done.stderr
    entry, status = statuses(report)
    assert status == {"red": "baked", "blue": "baked", "spare": "unused"}
    assert entry["status"] == "saved"
    # red and blue differ in colour only: one paint type, baked once, shared.
    luts = sorted((tmp_path / "paint_lut").glob("paintlut-*.exr"))
    assert len(luts) == 1
    key = luts[0].stem.removeprefix("paintlut-")
    assert entry["shared"] == {key: ["blue", "red"]}
    computed = sorted(entry["materials"][name]["computed"] for name in ("red", "blue"))
    assert computed == [[], ["lut", "CYCLES", "EEVEE", "OSL"]]  # the second found the first's bake
    assert set(entry["materials"]["blue"]["fit"]) == {"CYCLES", "EEVEE"}
    for engine, fit in entry["materials"]["blue"]["fit"].items():  # the measure, whole and over the grazing band
        drawn = {"mode", "exact_at_one_sample", "samples"} if engine == "EEVEE" else set()  # how EEVEE draws it
        assert set(fit) == {"error", "target", "grazing", "grazing_target"} | drawn
    assert entry["materials"]["blue"]["fit"]["EEVEE"]["mode"] == "CONVERGED"  # the scene's default
    assert "one bake of paint type" in done.stdout and "shared by blue, red" in done.stdout
    assert not list(tmp_path.glob("*.partial*")) and not (tmp_path / "scene.blend1").exists()
    # The saved file refers to its LUTs relative to itself and is wired.
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    for name in ("red", "blue"):
        settings = bpy.data.materials[name].paint_lut
        assert settings.lut_path.startswith("//paint_lut/") and not settings.stale
        assert addon.nodes.group_of(bpy.data.materials[name]) is not None
    assert not bpy.data.materials["spare"].paint_lut.lut_path

    mtime = blend.stat().st_mtime_ns
    done = run(blend, "--report", report)
    assert done.returncode == 0, done.stderr
    entry, status = statuses(report)
    assert status == {"red": "cached", "blue": "cached", "spare": "unused"}
    assert entry["status"] == "unchanged" and blend.stat().st_mtime_ns == mtime

    edit_blend(blend, "blue", rho=(0.9, 0.1, 0.1))  # a colour: a node input, nothing to bake
    done = run(blend, "--report", report)
    _, status = statuses(report)
    assert status == {"red": "cached", "blue": "cached", "spare": "unused"}
    edit_blend(blend, "blue", g=0.4)  # the paint type: a bake of its own
    done = run(blend, "--report", report)
    _, status = statuses(report)
    assert status == {"red": "cached", "blue": "baked", "spare": "unused"}
    assert len(list((tmp_path / "paint_lut").glob("paintlut-*.exr"))) == 2

    # A damaged LUT is rebaked, not trusted and not a crash.
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    red = tmp_path / bpy.data.materials["red"].paint_lut.lut_path[2:]
    red.write_bytes(red.read_bytes()[: red.stat().st_size // 2])
    done = run(blend, "--report", report)
    assert done.returncode == 0, done.stderr
    _, status = statuses(report)
    assert status == {"red": "baked", "blue": "cached", "spare": "unused"}
    lut = pytest.importorskip("lut")
    lut.load_lut(red)  # whole and verified again


def test_broken_inputs_fail_alone(tmp_path):
    good = make_blend(tmp_path / "good.blend")
    bad_paint = make_blend(tmp_path / "bad_paint.blend")
    bpy.ops.wm.open_mainfile(filepath=str(bad_paint))
    bpy.data.materials["red"].paint_lut["n"] = -2.0  # as a script or a newer version might store it
    bpy.ops.wm.save_as_mainfile(filepath=str(bad_paint))
    text = tmp_path / "notes.blend"
    text.write_text("not a blend file\n")
    report = tmp_path / "report.json"

    done = run(tmp_path / "missing.blend", text, bad_paint, good, "--report", report)
    assert done.returncode == 1
    entries = json.loads(report.read_text())
    missing, not_blend, partly, whole = entries
    assert missing["status"] == "failed" and "no such file" in missing["reason"]
    assert not_blend["status"] == "failed" and "not a .blend file" in not_blend["reason"]
    assert text.read_text() == "not a blend file\n"
    assert partly["materials"]["red"]["status"] == "failed"
    assert "n must be" in partly["materials"]["red"]["reason"]
    assert partly["materials"]["blue"]["status"] == "baked" and partly["status"] == "saved"
    assert {m["status"] for m in whole["materials"].values()} == {"baked", "unused"}
    assert "red: failed: n must be" in done.stdout


def test_parallel_jobs_give_the_same_report(tmp_path):
    files = [make_blend(tmp_path / f"{i}.blend", used=(f"m{i}",), unused=()) for i in range(2)]
    report = tmp_path / "report.json"
    done = run(*files, "--jobs", "2", "--report", report)
    assert done.returncode == 0, done.stderr
    entries = json.loads(report.read_text())
    assert [e["file"] for e in entries] == [str(f.resolve()) for f in files]
    assert [{n: m["status"] for n, m in e["materials"].items()} for e in entries] == [{"m0": "baked"}, {"m1": "baked"}]


def test_the_shipped_command_runs_without_the_script(tmp_path, capsys):
    """addon.batch.main, as the extension ships it: in this process, and its
    parallel children started by module name, not by scripts/batch_bake.py."""
    files = [make_blend(tmp_path / f"{i}.blend", used=(f"m{i}",), unused=()) for i in range(2)]
    report = tmp_path / "report.json"
    assert batch.main([*map(str, files), "--jobs", "2", "--report", str(report)]) == 0
    assert [{n: m["status"] for n, m in e["materials"].items()} for e in report_of(report)] == [
        {"m0": "baked"},
        {"m1": "baked"},
    ]
    assert batch.main([str(files[0]), "--report", str(report)]) == 0
    assert report_of(report)[0]["materials"]["m0"]["status"] == "cached"
    assert f"{files[0].resolve()}: unchanged (1 cached)" in capsys.readouterr().out


def test_bad_arguments_name_the_parameter(tmp_path):
    done = run(tmp_path / "x.blend", "--jobs", "0")
    assert done.returncode == 2
    assert "--jobs must be an integer >= 1, got 0" in done.stderr
    # As under `blender -b -P scripts/batch_bake.py -- ...`: arguments after '--'.
    done = run("--", tmp_path / "x.blend", "--jobs", "0")
    assert done.returncode == 2 and "--jobs must be" in done.stderr


def test_an_interrupted_save_keeps_the_old_file(tmp_path, monkeypatch):
    blend = make_blend(tmp_path / "scene.blend")
    before = blend.read_bytes()
    bpy.ops.wm.open_mainfile(filepath=str(blend))

    def dies_midway(filepath):
        pathlib.Path(filepath).write_bytes(b"BLENDER-half")
        raise RuntimeError("interrupted")

    monkeypatch.setattr(batch, "_write_blend", dies_midway)
    with pytest.raises(RuntimeError, match="interrupted"):
        batch.save_atomically(blend)
    assert blend.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["scene.blend"]


def test_pack_puts_the_weight_images_in_the_blend(tmp_path):
    blend = make_blend(tmp_path / "scene.blend", used=("red",), unused=())
    done = run(blend, "--pack")
    assert done.returncode == 0, done.stderr
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    images = [img for img in bpy.data.images if img.source == "FILE"]
    assert len(images) == 2  # the Cycles and EEVEE weights
    assert all(img.packed_file is not None for img in images)
