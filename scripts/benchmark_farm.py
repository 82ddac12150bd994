"""Farm benchmark: wall time and number of paint type bakes of a batch run
over N .blend files sharing K rough paint types, spread over folders, with
``--jobs 2`` (one machine's process pool) and with a Dask cluster of two
local workers (``--scheduler local:2``), each with the bakes beside every
file (``//paint_lut``, one per folder) and with one shared store
(``--store``).

    .venv/bin/python scripts/benchmark_farm.py [--files 40] [--types 4] [--folders 8]

Each configuration bakes a fresh copy of the same files (nothing cached).
Prints a Markdown table."""

from __future__ import annotations

import argparse
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

import addon  # noqa: E402

BATCH = ROOT / "scripts" / "batch_bake.py"

#: Rough paint types (slope, distribution): each bakes in 1-2 s here.
TYPES = ((0.2, "GAUSSIAN"), (0.4, "GAUSSIAN"), (0.3, "EXPONENTIAL"), (0.6, "EXPONENTIAL"), (0.8, "GAUSSIAN"))

CONFIGS = {
    "--jobs 2, per folder": ["--jobs", "2"],
    "--jobs 2, shared store": ["--jobs", "2", "--store", "{store}"],
    "Dask local:2, per folder": ["--scheduler", "local:2"],
    "Dask local:2, shared store": ["--scheduler", "local:2", "--store", "{store}"],
}


def make_files(root: pathlib.Path, count: int, types: int, folders: int) -> list[pathlib.Path]:
    """``count`` files, file i in folder i % folders, with two materials of
    the types i % types and (i + 1) % types in colours of their own."""
    paths = []
    for i in range(count):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        for j, t in enumerate((i % types, (i + 1) % types)):
            material = bpy.data.materials.new(f"paint {j}")
            material.paint_lut.enabled = True
            material.paint_lut.slope, material.paint_lut.distribution = TYPES[t][0], TYPES[t][1]
            material.paint_lut.rho = (0.05 + 0.02 * i % 0.9, 0.3, 0.2 + 0.1 * j)
            mesh = bpy.data.meshes.new(f"mesh {j}")
            mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
            mesh.materials.append(material)
            bpy.context.scene.collection.objects.link(bpy.data.objects.new(f"object {j}", mesh))
        path = root / f"folder{i % folders}" / f"shot{i:03d}.blend"
        path.parent.mkdir(parents=True, exist_ok=True)
        bpy.ops.wm.save_as_mainfile(filepath=str(path))
        paths.append(path)
    return paths


def bakes(entries) -> int:
    """How many paint type bakes computed a LUT in the run."""
    farm_types = {(key, t["store"]): t for e in entries for key, t in e.get("types", {}).items()}
    if farm_types:
        return sum("lut" in t.get("computed", []) for t in farm_types.values())
    return sum("lut" in m.get("computed", []) for e in entries for m in e["materials"].values())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--files", type=int, default=40)
    parser.add_argument("--types", type=int, default=4, choices=range(1, len(TYPES) + 1))
    parser.add_argument("--folders", type=int, default=8)
    args = parser.parse_args(argv)
    addon.register()
    with tempfile.TemporaryDirectory(prefix="farm_benchmark") as tmp:
        template = pathlib.Path(tmp) / "template"
        make_files(template, args.files, args.types, args.folders)
        print(f"{args.files} files in {args.folders} folders, {args.types} paint types, two per file\n")
        print("| run | wall time | paint type bakes | files saved |")
        print("|---|---|---|---|")
        for name, flags in CONFIGS.items():
            work = pathlib.Path(tmp) / "work"
            shutil.rmtree(work, ignore_errors=True)
            shutil.copytree(template, work / "shots")
            report = work / "report.json"
            files = sorted((work / "shots").rglob("*.blend"))
            command = [sys.executable, str(BATCH), *map(str, files), "--report", str(report)]
            command += [f.format(store=work / "store") for f in flags]
            start = time.perf_counter()
            done = subprocess.run(command, capture_output=True, text=True)
            seconds = time.perf_counter() - start
            if not report.exists():
                print(f"| {name} | failed: {done.stderr.strip().splitlines()[-1:]} | | |")
                continue
            entries = json.loads(report.read_text())
            saved = sum(e["status"] == "saved" for e in entries)
            print(f"| {name} | {seconds:.1f} s | {bakes(entries)} | {saved} of {len(entries)} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
