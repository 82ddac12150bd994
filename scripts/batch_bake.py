"""Bake the paint materials of .blend files headless, for pipelines and farms.

    .venv/bin/python scripts/batch_bake.py SCENE.blend [more.blend ...] [--force] [--pack]
                                           [--report FILE] [--jobs N]
    blender -b --factory-startup -P scripts/batch_bake.py -- SCENE.blend ... [options]

Per file: open it, bake the paint materials its objects use, skip unused and
up-to-date ones (the LUT cache), save it atomically (addon.batch).  Writes a
JSON report (--report) and prints a summary; exits 1 if any file or material
failed (or a linked material's library holds no current bake), 2 on bad
arguments (an unwritable --report is found before any work)."""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def parse(argv):
    parser = argparse.ArgumentParser(
        prog="batch_bake.py", description="Bake the paint materials that .blend files use, and save them."
    )
    parser.add_argument("files", nargs="+", metavar="SCENE.blend", help=".blend files to bake")
    parser.add_argument("--force", action="store_true", help="bake even what is up to date")
    parser.add_argument("--pack", action="store_true", help="pack the weight images into the .blend")
    parser.add_argument("--report", metavar="FILE", help="write the JSON report here")
    parser.add_argument("--jobs", type=int, default=1, metavar="N", help="files baked in parallel processes")
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f"--jobs must be an integer >= 1, got {args.jobs}")
    if args.report:
        problem = report_problem(pathlib.Path(args.report))
        if problem:
            parser.error(f"--report {args.report}: {problem}")
    return args


def report_problem(path: pathlib.Path):
    """Why the report cannot be written there (checked before any work), or None."""
    if path.is_dir():
        return "is a directory"
    parent = path.parent if str(path.parent) else pathlib.Path(".")
    if not parent.is_dir():
        return f"no such directory {parent}"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"directory {parent} is not writable"
    return None


def script_argv():
    """Our arguments: after '--' inside Blender, else the command line's."""
    if "--" in sys.argv:
        return sys.argv[sys.argv.index("--") + 1 :]
    return sys.argv[1:]


def progress(items, total):
    """tqdm's bar on a terminal (when installed); plain items otherwise."""
    if sys.stderr.isatty():
        try:
            from tqdm import tqdm

            return tqdm(items, total=total, unit="file", desc="baking")
        except ImportError:
            pass
    return items


def bake_here(args):
    """Bake the files in this process."""
    import addon
    from addon import batch

    addon.register()
    try:
        return [
            batch.bake_file(path, force=args.force, pack=args.pack) for path in progress(args.files, len(args.files))
        ]
    finally:
        addon.unregister()


def _child_prefix():
    """How to start a child: Blender running this script when we run inside
    Blender (bpy already loaded by it), else this Python."""
    bpy = sys.modules.get("bpy")
    if bpy is not None and pathlib.Path(bpy.app.binary_path).name.lower().startswith("blender"):
        return [bpy.app.binary_path, "-b", "--factory-startup", "-P", str(pathlib.Path(__file__)), "--"]
    return [sys.executable, str(pathlib.Path(__file__))]


def bake_parallel(args):
    """One process per file, at most ``--jobs`` at a time (Blender's data is
    one file per process); their reports go to a temporary directory that
    is removed afterwards."""
    with tempfile.TemporaryDirectory(prefix="batch_bake") as tmp:
        return _bake_in_children(args, pathlib.Path(tmp))


def _bake_in_children(args, tmp):
    prefix = _child_prefix()
    flags = [*(["--force"] if args.force else []), *(["--pack"] if args.pack else [])]

    def one(i, path):
        report = tmp / f"{i}.json"
        command = [*prefix, str(path), "--report", str(report), *flags]
        done = subprocess.run(command, capture_output=True, text=True)
        if report.exists():
            return json.loads(report.read_text())[0]
        reason = (done.stderr.strip().splitlines() or ["no report"])[-1]
        return {"file": str(pathlib.Path(path).resolve()), "status": "failed", "reason": reason, "materials": {}}

    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(one, i, path) for i, path in enumerate(args.files)]
        return [f.result() for f in progress(futures, len(futures))]


def main(argv=None) -> int:
    args = parse(script_argv() if argv is None else argv)
    try:
        entries = bake_parallel(args) if args.jobs > 1 and len(args.files) > 1 else bake_here(args)
    except KeyboardInterrupt:
        print("interrupted: files already saved keep their bakes", file=sys.stderr)
        return 130
    from addon import batch

    print(batch.summary(entries))
    if args.report:
        from lut import lutfile

        try:
            lutfile.atomic_write_bytes(args.report, (json.dumps(entries, indent=2) + "\n").encode())
        except OSError as exc:
            print(f"error: cannot write the report {args.report}: {exc}", file=sys.stderr)
            return 2
    return 1 if batch.failed(entries) else 0


if __name__ == "__main__":
    sys.exit(main())  # Blender too exits with this code after -P
