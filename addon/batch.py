"""Headless batch baking of .blend files, for farms: ``main`` is the command
line (scripts/batch_bake.py runs it from the repository).

One file at a time: open it, bake the paint materials it renders (what its
scenes' depsgraphs evaluate: object slots, collection instances, Geometry
Nodes' Set Material; ``api.used_materials``) and the paint materials it
offers as assets, skip unused and up-to-date ones, and save it atomically
when anything was baked.  Every failure is reported per item with its reason
and never stops the others:

* a file that is missing or not a .blend fails and is never written;
* a material whose paint is invalid, or whose bake fails in any way, fails
  alone, keeps its previous state, and the file is still saved with the
  other materials' bakes;
* a corrupted or missing LUT or weights file is rebaked.

A material linked from a library is never baked here (Blender does not save
edits to linked data): it is reported ``linked`` with its library, the file
to bake it in, and whether the library holds a current bake of it.

Saving writes a temporary file next to the .blend and renames it into place,
so an interrupted run never leaves a half-written .blend (no .blend1 backup
either: the old file is replaced only by a complete new one); the file keeps
its permissions."""

from __future__ import annotations

import argparse
import concurrent.futures
import contextlib
import importlib
import json
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import threading
import tomllib

import bpy

from . import api, nodes
from ._lut import baking, closures, farm, files, fitting, lut
from .library import ASSETS, LIBRARY_BLEND

#: The first bytes of a .blend file: plain, gzip (Blender < 3) or zstd compressed.
_MAGIC = (b"BLENDER", b"\x1f\x8b", b"\x28\xb5\x2f\xfd")


def check_blend(path: pathlib.Path) -> None:
    """Raise ValueError naming the file unless it exists and looks like a .blend."""
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    with path.open("rb") as fh:
        head = fh.read(8)
    if not head.startswith(_MAGIC):
        raise ValueError(f"{path}: not a .blend file")


def save_atomically(path: pathlib.Path, pack=False) -> None:
    """Save the open file to ``path`` through a temporary file and a rename."""
    if pack:
        for image in bpy.data.images:
            if image.source == "FILE" and image.packed_file is None and image.filepath:
                image.pack()
    with files.atomic_target(path) as tmp:
        os.remove(tmp)  # let Blender create it: no .blend1 of the placeholder
        try:
            _write_blend(tmp)
        except RuntimeError as exc:  # Blender's message names the hidden temporary file: name the file
            raise RuntimeError(str(exc).replace(str(tmp), path.name).strip()) from None


def _write_blend(filepath):
    """Blender writes the open file (as a copy: the session keeps its path;
    same folder, so relative paths stay valid)."""
    bpy.ops.wm.save_as_mainfile(filepath=filepath, copy=True, relative_remap=False)


def materials_to_bake(scenes) -> set:
    """The materials a file must bake: those its scenes render
    (``api.used_materials``), its own material assets (an asset kept with
    a fake user for other files to link is used, here in its own file), and
    its materials kept by a fake user alone (a library of the classic,
    pre-asset kind: other files link them)."""
    kept = {
        m
        for m in bpy.data.materials
        if m.library is None and (m.asset_data is not None or (m.use_fake_user and m.users == 1))
    }
    return api.used_materials(scenes) | kept


@contextlib.contextmanager
def _blender_chatter_to_stderr():
    """Blender prints "Read blend: ..." on standard output when it opens a
    file: send it to standard error for the block, so the batch's standard
    output is its summary alone."""
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):
        yield
        return
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def bundled(path) -> bool:
    """Whether ``path`` is the add-on's own asset library, of this install
    or of another Blender version's (an ``assets`` folder holding that file
    beside this extension's manifest): a file the batch links from but never
    writes (it ships with the extension, saved by the oldest Blender the
    extension supports)."""
    path = pathlib.Path(os.path.realpath(path))
    if path.parent == pathlib.Path(os.path.realpath(ASSETS)):
        return True
    if path.name != LIBRARY_BLEND.name or path.parent.name != ASSETS.name:
        return False
    manifest = path.parent.parent / "blender_manifest.toml"
    try:
        return tomllib.loads(manifest.read_text()).get("id") == EXTENSION_ID
    except (OSError, ValueError):
        return False


#: The extension's id (blender_manifest.toml): what marks another install's bundled library.
EXTENSION_ID = "paint_lut"


def _report_name(material) -> str:
    """A material's key in the report: its name, or for a linked one its
    name and library ("paint [lib.blend]"), which a local one may share."""
    return material.name if material.library is None else material.name_full


def linked_status(material, exact_metallic=None) -> dict:
    """The report entry of a material linked from a library: where to bake
    it and whether that library holds a current bake (the settings are not
    stale, and the LUT, both weights files (of ``exact_metallic`` lobes, as
    ``api.bake_material`` takes it) and the node groups are there and
    verified)."""
    library = pathlib.Path(bpy.path.abspath(material.library.filepath)).resolve()
    if bundled(library):
        return {
            "status": "linked", "library": str(library), "baked": False, "bundled": True,
            "reason": "linked from the add-on's bundled library: renders its Principled fallback "
            "(append the material to bake it in this file)",
        }  # fmt: skip
    settings = material.paint_lut
    baked = False
    if not settings.stale and settings.lut_path:
        path = pathlib.Path(bpy.path.abspath(settings.lut_path, library=material.library))
        try:
            table = lut.load_lut(path)
            exact = nodes.exact_metallic_default(exact_metallic)
            for target in closures.TARGETS:
                # The EEVEE mode the library baked it in (its group says), not this file's.
                node = nodes.group_of(material, "EEVEE")
                mode = node.node_tree.get("paint_lut_eevee_mode", "EXACT") if node is not None else "EXACT"
                fit_file = fitting.fit_path(path, target, exact, api.eevee_calibration(), mode)
                fitted = fitting.read_fit(fit_file)
                baked_node = nodes.group_of(material, target)
                if fitted.lut_key != table.key or baked_node is None or not nodes.is_paint_group(baked_node.node_tree):
                    raise lut.LUTError("not wired to this bake")
            baked = True
        except lut.LUTError:
            baked = False
    reason = f"linked from {library}: bake it there (batch_bake.py {library})"
    if not baked:
        reason = f"not baked in its library; {reason}"
    return {"status": "linked", "library": str(library), "baked": baked, "reason": reason}


def bake_one(material, used, force=False, rewire=False, **options) -> dict:
    """Bake one paint material if it is used and not current; its report
    entry.  ``force``: bake it again; ``rewire``: wire it anew from its
    type's bake even when current (a farm's forced run, whose types were
    baked again already).  Any exception fails this material alone, with
    its reason."""
    if material.library is not None:
        return linked_status(material, options.get("exact_metallic")) if material in used else {"status": "unused"}
    if material not in used:
        return {"status": "unused"}
    try:
        paint = api.paint_of(material)
        if not (force or rewire) and api.is_current(material, paint, **options):
            return {"status": "cached", **_fit_entry(material)}
        result = api.bake_material(material, force=force, **options)
    except (ValueError, OSError, RuntimeError) as exc:
        return {"status": "failed", "reason": str(exc).strip() or type(exc).__name__}
    except Exception as exc:  # a defect must not cost the file its other bakes
        return {"status": "failed", "reason": f"{type(exc).__name__}: {exc}"}
    return {"status": "baked", "computed": list(result.computed), **_fit_entry(material)}


def _fit_entry(material) -> dict:
    """The paint type's LUT key (materials with one key shared one bake) and
    each engine's fit error at the material's colours (the fidelity measure,
    whole and over the grazing band), with their targets; for EEVEE also
    how it draws the material (``api.FitError``)."""
    entry = {"type": pathlib.Path(material.paint_lut.lut_path).stem.removeprefix("paintlut-")}
    errors = api.fit_errors(material)
    entry["fit"] = {
        t: {
            "error": round(f.error, 5),
            "target": f.target,
            "grazing": round(f.grazing, 5),
            "grazing_target": f.grazing_target,
            # How EEVEE draws it: the scene's mode, whether at one sample
            # exactly, and the samples its noisiest colour needs.
            **({"mode": f.eevee_mode, "exact_at_one_sample": f.exact, "samples": f.samples} if f.eevee_mode else {}),
        }
        for t, f in errors.items()
    }
    # What Cycles draws of it in the file's scene: "OSL" (its OSL variant,
    # whose errors are listed as "OSL") or "SVM".
    entry["cycles_variant"] = api.cycles_variant(material)
    if material.paint_lut.osl_problem:  # the OSL variant was asked for and could not be built here
        entry["osl_problem"] = material.paint_lut.osl_problem
    misses = []
    for t, f in errors.items():
        if f.error > f.target:
            misses.append(f"{_label(t)} {100 * f.error:.1f}% > {100 * f.target:.0f}%")
        if f.grazing > f.grazing_target:
            misses.append(f"{_label(t)} grazing light {100 * f.grazing:.1f}% > {100 * f.grazing_target:.0f}%")
    if misses:
        entry["fit_misses"] = misses
    return entry


def _label(target: str) -> str:
    return "Cycles OSL" if target == api.OSL_VARIANT else target.title()


def shared_bakes(materials: dict) -> dict:
    """{LUT key: [material names]} for the paint types that several of a
    file's materials share (baked once, the others found it cached)."""
    groups = {}
    for name, m in materials.items():
        if m.get("type"):
            groups.setdefault(m["type"], []).append(name)
    return {key: names for key, names in groups.items() if len(names) > 1}


def _open(path, entry):
    """Open a .blend for the batch and return the materials it must bake,
    or None with the entry failed and its reason."""
    try:
        check_blend(path)
        if bundled(path):
            raise ValueError(
                f"{path} is the add-on's own asset library: never written (append its materials to bake them)"
            )
        with _blender_chatter_to_stderr():
            bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except (ValueError, RuntimeError) as exc:
        entry.update(status="failed", reason=str(exc).strip())
        return None
    try:
        return materials_to_bake(bpy.data.scenes)
    except Exception as exc:  # the file cannot be evaluated: nothing is baked or saved
        entry.update(status="failed", reason=f"cannot find the materials it uses: {type(exc).__name__}: {exc}")
        return None


def scan_file(path, store=None) -> dict:
    """The paint types a .blend file's used materials need (the farm's
    first phase, ``lut.farm``): its report entry {"file", "status":
    "scanned" (or "failed" with its "reason"), "paint_types": [{"key", "store",
    "paint", "exact_metallic", "eevee_calibration", "eevee_mode", "materials"}]}, one per
    type and folder, a type's paint being its first material's.  A material
    whose paint is invalid is left to the bake, which reports it."""
    path = pathlib.Path(path).resolve()
    entry = {"file": str(path), "materials": {}}
    used = _open(path, entry)
    if used is None:
        return entry
    directory = pathlib.Path(store) if store else api.lut_directory()
    calibration = api.eevee_calibration()
    types = {}
    for material in bpy.data.materials:
        if not material.paint_lut.enabled or material.library is not None or material not in used:
            continue
        try:
            paint = api.paint_of(material)
        except ValueError:
            continue
        key = baking.lut_path(paint, directory).stem.removeprefix("paintlut-")
        spec = types.setdefault(
            key,
            {
                "key": key,
                "store": str(directory.resolve()),
                "paint": paint.to_dict(),
                "exact_metallic": nodes.exact_metallic_default(None),
                "eevee_calibration": list(calibration) if calibration else None,
                "eevee_mode": api.eevee_mode(),
                "materials": [],
            },
        )
        spec["materials"].append(_report_name(material))
    entry.update(status="scanned", paint_types=list(types.values()))
    return entry


def bake_file(path, force=False, pack=False, rewire=False, **options) -> dict:
    """Bake one .blend file.  Returns its report entry: {"file", "status"
    ("saved", "unchanged" or "failed"), "reason" (when failed), "materials":
    {name: {"status": "baked" | "cached" | "unused" | "linked" | "failed",
    "reason", and for linked ones "library" and "baked"}}}.  ``options``:
    ``api.bake_material``'s (``directory``: where the bakes go, default the
    file's ``//paint_lut``).  Never raises."""
    path = pathlib.Path(path).resolve()
    entry = {"file": str(path), "materials": {}}
    used = _open(path, entry)
    if used is None:
        return entry
    for material in list(bpy.data.materials):
        if material.paint_lut.enabled:
            entry["materials"][_report_name(material)] = bake_one(material, used, force=force, rewire=rewire, **options)
    shared = shared_bakes(entry["materials"])
    if shared:
        entry["shared"] = shared
    baked = any(m["status"] == "baked" for m in entry["materials"].values())
    if baked or pack:
        try:
            if not path.stat().st_mode & 0o222:  # by its mode bits: root may write anything
                raise PermissionError(f"{path.name} is read-only: kept as it is (make it writable to save its bakes)")
            save_atomically(path, pack=pack)
        except (OSError, RuntimeError) as exc:
            entry.update(status="failed", reason=f"cannot save {path}: {exc}")
            for m in entry["materials"].values():
                if m["status"] == "baked":  # its bake is not in the file
                    m.update(status="failed", reason="baked, but the file could not be saved")
            return entry
        entry["status"] = "saved"
    else:
        entry["status"] = "unchanged"
    reason = _materials_reason(entry["materials"])
    if reason:
        entry["reason"] = reason
    return entry


def _materials_reason(materials) -> str:
    """What failed among a file's materials, by name: those that failed, and
    the linked ones whose library holds no current bake."""
    failed_names = [name for name, m in materials.items() if m["status"] == "failed"]
    unbaked = [name for name, m in materials.items() if _unbaked_link(m)]
    parts = []
    if failed_names:
        parts.append(f"{len(failed_names)} failed ({', '.join(failed_names)})")
    if unbaked:
        parts.append(f"{len(unbaked)} linked, not baked in their library ({', '.join(unbaked)})")
    return "; ".join(parts)


def _unbaked_link(material_entry) -> bool:
    """A link to a library that holds no current bake (the bundled library's
    materials keep their fallback, as documented: not a failure)."""
    m = material_entry
    return m["status"] == "linked" and not m.get("baked") and not m.get("bundled")


def _failed(material_entry) -> bool:
    return material_entry["status"] == "failed" or _unbaked_link(material_entry)


def failed(entries) -> bool:
    """Whether any file or material of a report failed (a linked material
    whose library holds no current bake renders unbaked: that fails too)."""
    return any(e["status"] == "failed" or any(_failed(m) for m in e["materials"].values()) for e in entries)


def summary(entries) -> str:
    """One line per file (its status and material counts), one per failed or linked material."""
    lines = []
    for entry in entries:
        counts = {}
        for m in entry["materials"].values():
            counts[m["status"]] = counts.get(m["status"], 0) + 1
        text = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
        if not text and entry["status"] != "failed":  # a failed file may not have been read at all
            text = "no paint materials"
        lines.append(
            f"{entry['file']}: {entry['status']}"
            + (f" ({text})" if text else "")
            + (f": {entry['reason']}" if "reason" in entry else "")
        )
        for name, m in entry["materials"].items():
            if m["status"] in ("failed", "linked"):
                lines.append(f"  {name}: {m['status']}: {m['reason']}")
            if m.get("fit_misses"):
                lines.append(f"  {name}: fit misses its target: {', '.join(m['fit_misses'])}")
        for key, names in entry.get("shared", {}).items():
            lines.append(f"  one bake of paint type {key[:12]} shared by {', '.join(names)}")
    # A farm run's bakes: one per type and folder (a type used in two
    # folders without a shared store is baked in each).
    types = {(key, t.get("store")): t for entry in entries for key, t in entry.get("types", {}).items()}
    folders = {store for _, store in types}
    for (key, store), t in types.items():
        where = f" in {store}" if len(folders) > 1 else ""
        if "failed" in t:
            lines.append(f"paint type {key[:12]}{where}: its bake failed on the cluster ({t['failed']})")
        elif t["computed"]:
            lines.append(
                f"paint type {key[:12]}{where}: baked on {t['worker']} in {t['seconds']:.1f} s"
                f" ({', '.join(t['computed'])})"
            )
        else:
            lines.append(f"paint type {key[:12]}{where}: found baked ({t['worker']})")
    return "\n".join(lines)


# ----------------------------------------------------------------------------- the command line


def parse(argv):
    parser = argparse.ArgumentParser(
        prog="batch_bake.py", description="Bake the paint materials that .blend files use, and save them."
    )
    parser.add_argument("files", nargs="+", metavar="SCENE.blend", help=".blend files to bake")
    parser.add_argument("--force", action="store_true", help="bake even what is up to date")
    parser.add_argument("--pack", action="store_true", help="pack the weight images into the .blend")
    parser.add_argument("--report", metavar="FILE", help="write the JSON report here")
    parser.add_argument("--jobs", type=int, default=1, metavar="N", help="files baked in parallel processes")
    parser.add_argument(
        "--store", metavar="DIR", help="bake every paint type into this folder (default: //paint_lut beside each file)"
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDR",
        help="bake on a Dask cluster: local:N (N worker processes here) or a scheduler address, tcp://host:8786",
    )
    parser.add_argument(
        "--files-per-task",
        type=int,
        default=farm.FILES_PER_TASK,
        metavar="N",
        help=f"with --scheduler: files per Blender process on a worker (default {farm.FILES_PER_TASK})",
    )
    parser.add_argument("--scan", action="store_true", help=argparse.SUPPRESS)  # the farm's first phase
    parser.add_argument("--rewire", action="store_true", help=argparse.SUPPRESS)  # a farm's forced run, phase 3
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f"--jobs must be an integer >= 1, got {args.jobs}")
    if args.scheduler is not None:
        try:
            farm.validate_scheduler(args.scheduler)
        except ValueError as exc:
            parser.error(f"--scheduler: {exc}")
        if args.jobs > 1:
            parser.error("--jobs and --scheduler exclude each other: the cluster's workers bake in parallel")
    if args.files_per_task < 1:
        parser.error(f"--files-per-task must be an integer >= 1, got {args.files_per_task}")
    if args.store is not None:
        store = pathlib.Path(args.store)
        blocker = next((p for p in (store, *store.parents) if p.exists()), None)
        if blocker is not None and not blocker.is_dir():
            parser.error(f"--store {args.store}: {blocker} is not a directory")
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
    """Bake the files in this process, with the add-on registered (here, for
    the run, unless it is already: an enabled extension)."""
    package = importlib.import_module(__package__)
    registered = hasattr(bpy.types.Material, "paint_lut")
    if not registered:
        package.register()
    options = {"directory": pathlib.Path(args.store).resolve()} if args.store else {}
    try:
        if args.scan:
            return [scan_file(path, args.store) for path in args.files]
        return [
            bake_file(path, force=args.force, pack=args.pack, rewire=args.rewire, **options)
            for path in progress(args.files, len(args.files))
        ]
    finally:
        if not registered:
            package.unregister()


def child_command(script=None) -> list:
    """How to start a child process that bakes one file: ``script`` (a file
    that runs ``main``, e.g. scripts/batch_bake.py) or else this module's
    ``main`` imported by name; run by Blender in the background when we run
    inside Blender (bpy loaded by it), else by this Python."""
    in_blender = pathlib.Path(bpy.app.binary_path).name.lower().startswith("blender")
    if script is not None:
        if in_blender:
            return [bpy.app.binary_path, "-b", "--factory-startup", "-P", str(script), "--"]
        return [sys.executable, str(script)]
    top = sys.modules[__name__.partition(".")[0]]
    root = [str(pathlib.Path(top.__file__).resolve().parents[1])] if getattr(top, "__file__", None) else []
    # bpy first: an installed extension's package (bl_ext...) exists once Blender has set up its repositories.
    code = (
        f"import bpy, importlib, sys; sys.path[:0] = {root!r}; sys.exit(importlib.import_module({__name__!r}).main())"
    )
    if in_blender:  # an extension is enabled by the preferences: keep them unless we run without
        factory = ["--factory-startup"] if "--factory-startup" in sys.argv else []
        return [bpy.app.binary_path, "-b", *factory, "--python-expr", code, "--"]
    return [sys.executable, "-c", code, "--"]


def bake_parallel(args, script=None):
    """One process per file, at most ``--jobs`` at a time (Blender's data is
    one file per process); their reports go to a temporary directory that
    is removed afterwards."""
    with tempfile.TemporaryDirectory(prefix="batch_bake") as tmp:
        return _bake_in_children(args, pathlib.Path(tmp), child_command(script))


def _bake_in_children(args, tmp, prefix):
    flags = [*(["--force"] if args.force else []), *(["--pack"] if args.pack else [])]
    flags += ["--store", str(pathlib.Path(args.store).resolve())] if args.store else []

    def one(i, path):
        report = tmp / f"{i}.json"
        command = [*prefix, str(path), "--report", str(report), *flags]
        done = subprocess.run(command, capture_output=True, text=True)
        if report.exists():
            return json.loads(report.read_text())[0]
        reason = (done.stderr.strip().splitlines() or ["no report"])[-1]
        return farm.failed_entry(path, reason)

    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(one, i, path) for i, path in enumerate(args.files)]
        return [f.result() for f in progress(futures, len(futures))]


def _terminated(signum, frame):
    raise KeyboardInterrupt


def main(argv=None, *, script=None) -> int:
    """The batch command line (``argv``: default the arguments after '--'
    inside Blender, else the command line's).  ``script``: the file the
    parallel children run (default: this module's ``main``).  Prints the
    summary, writes the JSON report (--report) and returns the exit status:
    0, 1 if any file or material failed (or a linked material's library
    holds no current bake), 2 on bad arguments or an unwritable report,
    130 when interrupted."""
    args = parse(script_argv() if argv is None else argv)
    if args.scheduler is not None and threading.current_thread() is threading.main_thread():
        # A job killer's SIGTERM unwinds like Ctrl-C, so the local cluster stops.
        signal.signal(signal.SIGTERM, _terminated)
    try:
        if args.scheduler is not None:
            try:
                entries = farm.run(
                    args.files,
                    args.scheduler,
                    child=child_command(script),
                    store=args.store,
                    force=args.force,
                    pack=args.pack,
                    files_per_task=args.files_per_task,
                )
            except farm.FarmUnavailable as exc:
                print(f"error: {exc}", file=sys.stderr)
                return 2
        elif args.jobs > 1 and len(args.files) > 1:
            entries = bake_parallel(args, script)
        else:
            entries = bake_here(args)
    except KeyboardInterrupt:
        print("interrupted: files already saved keep their bakes", file=sys.stderr)
        return 130
    print(summary(entries))
    if args.report:
        try:
            files.atomic_write_bytes(args.report, (json.dumps(entries, indent=2) + "\n").encode())
        except OSError as exc:
            print(f"error: cannot write the report {args.report}: {exc}", file=sys.stderr)
            return 2
    return 1 if failed(entries) else 0
