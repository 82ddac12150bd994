"""Batch baking on a Dask cluster (``lut.farm``, ``--scheduler``): each
paint type baked once for a whole run into one shared store, every file
wired and saved, a second run computing nothing, a worker killed mid-bake
costing a retry and no partial file, and the optional dependency's absence
named in one line."""

from __future__ import annotations

import contextlib
import json
import pathlib
import subprocess
import sys
import time

import pytest

bpy = pytest.importorskip("bpy")
pytest.importorskip("distributed")

from addon import api, batch  # noqa: E402
from lut import farm  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "batch_bake.py"

pytestmark = pytest.mark.usefixtures("addon_registered")

#: Three smooth paint types (quick to bake), told apart by their index.
TYPE_N = (1.4, 1.5, 1.6)


def make_shot(path, types, colours):
    """A .blend with one triangle per material, material i of paint type
    ``types[i]`` (an index of TYPE_N) and colour ``colours[i]``."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for i, (t, rho) in enumerate(zip(types, colours, strict=True)):
        material = bpy.data.materials.new(f"paint {i}")
        material.paint_lut.enabled = True
        material.paint_lut.slope = 0.0
        material.paint_lut.n = TYPE_N[t]
        material.paint_lut.rho = rho
        mesh = bpy.data.meshes.new(f"mesh {i}")
        mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
        mesh.materials.append(material)
        scene.collection.objects.link(bpy.data.objects.new(f"object {i}", mesh))
    path.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return path


def shots(root):
    """8 files in 3 folders sharing the 3 paint types in other colours."""
    layout = [
        ("a/1.blend", (0, 1)),
        ("a/2.blend", (1,)),
        ("a/3.blend", (2, 0)),
        ("b/4.blend", (0,)),
        ("b/5.blend", (2,)),
        ("b/6.blend", (1, 2)),
        ("c/7.blend", (0, 1, 2)),
        ("c/8.blend", (2,)),
    ]
    out = []
    for k, (name, types) in enumerate(layout):
        colours = [(0.1 + 0.1 * k, 0.2 + 0.05 * i, 0.5) for i in range(len(types))]
        out.append(make_shot(root / name, types, colours))
    return out


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)


def current(path, store):
    """Whether every paint material of the saved file is wired to a current
    bake in the store, its LUT referenced relative to the .blend."""
    bpy.ops.wm.open_mainfile(filepath=str(path))
    materials = [m for m in bpy.data.materials if m.paint_lut.enabled]
    return bool(materials) and all(
        api.is_current(m, api.paint_of(m), directory=store) and m.paint_lut.lut_path.startswith("//") for m in materials
    )


def test_each_type_is_baked_once_for_the_whole_run_and_a_second_run_computes_nothing(tmp_path):
    files = shots(tmp_path / "shots")
    bogus = tmp_path / "shots" / "c" / "bogus.blend"
    bogus.write_text("not a blend file")
    store = tmp_path / "store"
    report = tmp_path / "report.json"

    listed = [*files, bogus, files[0]]  # the first file listed twice: baked and saved once
    done = run(*listed, "--scheduler", "local:2", "--store", store, "--report", report)
    assert done.returncode == 1, done.stderr  # the bogus file fails alone
    entries = json.loads(report.read_text())
    assert [e["file"] for e in entries] == [str(f.resolve()) for f in listed]
    assert entries.pop() == entries[0]
    assert entries[-1]["status"] == "failed" and "not a .blend file" in entries[-1]["reason"]
    assert all(e["status"] == "saved" for e in entries[:-1]), [e.get("reason") for e in entries]
    types = {key: t for e in entries for key, t in e.get("types", {}).items()}
    assert len(types) == 3
    assert all(t["computed"] == ["lut", "CYCLES", "EEVEE"] for t in types.values())
    assert all(t["worker"] and t["seconds"] > 0 for t in types.values())
    # Every file that renders a type reports the same one bake of it.
    for e in entries[:-1]:
        for key, t in e["types"].items():
            assert t == types[key]
    assert len(list(store.glob("paintlut-*.exr"))) == 3
    assert not list(store.glob(".*partial*"))
    assert not list((tmp_path / "shots").rglob("paint_lut"))  # nothing beside the files
    assert "baked on" in done.stdout
    assert all(current(f, store) for f in files)

    again = run(*files, "--scheduler", "local:2", "--store", store, "--report", report)
    assert again.returncode == 0, again.stderr
    entries = json.loads(report.read_text())
    assert all(e["status"] == "unchanged" for e in entries)
    assert all(t["computed"] == [] for e in entries for t in e["types"].values())


def test_a_worker_killed_mid_bake_costs_a_retry_and_leaves_no_partial_file(tmp_path, monkeypatch):
    import farm_tasks

    monkeypatch.setenv("PYTHONPATH", str(pathlib.Path(farm_tasks.__file__).parent))  # the workers import it

    files = shots(tmp_path / "shots")[:3]
    store = tmp_path / "store"
    entries = farm.run(files, "local:2", child=batch.child_command(), store=store, bake=farm_tasks.bake_killed_once)
    assert (store / "killed-once").exists()  # a worker was killed
    assert all(e["status"] == "saved" for e in entries), [e.get("reason") for e in entries]
    types = {key: t for e in entries for key, t in e["types"].items()}
    assert len(types) == 3 and all("failed" not in t for t in types.values())
    assert not list(store.glob(".*partial*"))
    assert all(current(f, store) for f in files)

    # A forced run bakes every type again and wires and saves every file anew.
    forced = farm.run(files, "local:2", child=batch.child_command(), store=store, force=True)
    assert all(e["status"] == "saved" for e in forced), [e.get("reason") for e in forced]
    assert all(t["computed"] == ["lut", "CYCLES", "EEVEE"] for e in forced for t in e["types"].values())
    assert all(current(f, store) for f in files)


def test_a_crashing_child_fails_only_the_file_that_crashes_it(tmp_path):
    import farm_tasks

    good = shots(tmp_path / "shots")[:2]
    crash = make_shot(tmp_path / "shots" / "crash.blend", (0,), [(0.5, 0.5, 0.5)])
    child = [sys.executable, farm_tasks.__file__, "crash.blend"]
    entries = farm.run([good[0], crash, good[1]], "local:1", child=child, store=tmp_path / "store")
    assert [e["status"] for e in entries] == ["saved", "failed", "saved"], [e.get("reason") for e in entries]
    assert "exited with status -11" in entries[1]["reason"]
    assert all(current(f, tmp_path / "store") for f in good)


def test_a_cluster_that_cannot_start_blender_reports_every_file_failed(tmp_path):
    files = shots(tmp_path / "shots")[:2]
    entries = farm.run(files, "local:1", child=[str(tmp_path / "no-blender")], store=tmp_path / "store")
    assert [e["status"] for e in entries] == ["failed", "failed"]
    assert all("cannot scan on the cluster: FileNotFoundError" in e["reason"] for e in entries)


def test_a_terminated_run_stops_its_local_cluster(tmp_path):
    import psutil

    files = shots(tmp_path / "shots")[:2]
    process = subprocess.Popen([sys.executable, str(SCRIPT), *map(str, files), "--scheduler", "local:1"])
    deadline = time.monotonic() + 120
    cluster = []
    while time.monotonic() < deadline and not any("dask_worker" in " ".join(c.cmdline()) for c in cluster):
        time.sleep(0.2)
        with contextlib.suppress(psutil.Error):
            cluster = psutil.Process(process.pid).children(recursive=True)
    assert cluster, "the local cluster never started"
    process.terminate()
    assert process.wait(timeout=120) == 130
    _, alive = psutil.wait_procs(cluster, timeout=60)
    assert not alive


def test_the_summary_counts_one_bake_per_type_and_folder():
    bake = {"worker": "node:1", "seconds": 1.0, "computed": ["lut", "CYCLES", "EEVEE"]}
    entries = [
        {"file": f"/{d}/x.blend", "status": "saved", "materials": {}, "types": {"abc": {**bake, "store": f"/{d}/s"}}}
        for d in ("a", "b")
    ]
    lines = [line for line in batch.summary(entries).splitlines() if line.startswith("paint type")]
    assert lines == ["paint type abc in /a/s: baked on node:1 in 1.0 s (lut, CYCLES, EEVEE)", lines[1]]
    assert "in /b/s" in lines[1]


def test_a_store_under_a_file_is_refused_before_any_work(tmp_path):
    (tmp_path / "afile").write_text("")
    done = run(tmp_path / "none.blend", "--store", tmp_path / "afile" / "store")
    assert done.returncode == 2
    assert "is not a directory" in done.stderr


def test_without_dask_the_scheduler_flag_says_what_to_install(tmp_path):
    blend = shots(tmp_path)[0]
    code = (
        f"import sys; sys.modules['distributed'] = None; sys.path.insert(0, {str(ROOT)!r}); "
        f"from addon import batch; sys.exit(batch.main([{str(blend)!r}, '--scheduler', 'local:1']))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 2
    assert "pip install -r requirements-farm.txt" in done.stderr.strip().splitlines()[-1]


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--scheduler", "local:0"], "local:N with N a whole number >= 1"),
        (["--scheduler", "somehost"], "tcp://host:8786"),
        (["--scheduler", "local:2", "--jobs", "2"], "exclude each other"),
        (["--scheduler", "local:2", "--files-per-task", "0"], "--files-per-task must be an integer >= 1"),
    ],
)
def test_bad_scheduler_flags_are_refused_before_any_work(tmp_path, flags, message):
    done = run(tmp_path / "none.blend", *flags)
    assert done.returncode == 2
    assert message in done.stderr
