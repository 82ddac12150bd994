"""Headless batch baking of .blend files (for farms; scripts/batch_bake.py).

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

import os
import pathlib

import bpy

from . import api, nodes
from ._lut import closures, fitting, lut, lutfile

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
    with lutfile.atomic_target(path) as tmp:
        os.remove(tmp)  # let Blender create it: no .blend1 of the placeholder
        _write_blend(tmp)


def _write_blend(filepath):
    """Blender writes the open file (as a copy: the session keeps its path;
    same folder, so relative paths stay valid)."""
    bpy.ops.wm.save_as_mainfile(filepath=filepath, copy=True, relative_remap=False)


def materials_to_bake(scenes) -> set:
    """The materials a file must bake: those its scenes render
    (``api.used_materials``) and its own material assets (an asset kept with
    a fake user for other files to link is used, here in its own file)."""
    assets = {m for m in bpy.data.materials if m.library is None and m.asset_data is not None}
    return api.used_materials(scenes) | assets


def _report_name(material) -> str:
    """A material's key in the report: its name, or for a linked one its
    name and library ("paint [lib.blend]"), which a local one may share."""
    return material.name if material.library is None else material.name_full


def linked_status(material) -> dict:
    """The report entry of a material linked from a library: where to bake
    it and whether that library holds a current bake (the settings are not
    stale, and the LUT, both weights files and the node groups are there and
    verified)."""
    library = pathlib.Path(bpy.path.abspath(material.library.filepath)).resolve()
    settings = material.paint_lut
    baked = False
    if not settings.stale and settings.lut_path:
        path = pathlib.Path(bpy.path.abspath(settings.lut_path, library=material.library))
        try:
            table = lut.load_lut(path)
            for target in closures.TARGETS:
                fitted = fitting.read_fit(fitting.fit_path(path, target, nodes.EXACT_METALLIC, api.eevee_calibration()))
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


def bake_one(material, used, force=False, **options) -> dict:
    """Bake one paint material if it is used and not current; its report
    entry.  Any exception fails this material alone, with its reason."""
    if material.library is not None:
        return linked_status(material) if material in used else {"status": "unused"}
    if material not in used:
        return {"status": "unused"}
    try:
        paint = api.paint_of(material)
        if not force and api.is_current(material, paint, **options):
            return {"status": "cached", **_fit_entry(material)}
        result = api.bake_material(material, force=force, **options)
    except (ValueError, OSError, RuntimeError) as exc:
        return {"status": "failed", "reason": str(exc).strip() or type(exc).__name__}
    except Exception as exc:  # a defect must not cost the file its other bakes
        return {"status": "failed", "reason": f"{type(exc).__name__}: {exc}"}
    return {"status": "baked", "computed": list(result.computed), **_fit_entry(material)}


def _fit_entry(material) -> dict:
    """The paint type's LUT key (materials with one key shared one bake) and
    each engine's fit error at the material's colours, with its target."""
    entry = {"type": pathlib.Path(material.paint_lut.lut_path).stem.removeprefix("paintlut-")}
    errors = api.fit_errors(material)
    entry["fit"] = {t: {"error": round(e, 5), "target": g} for t, (e, g) in errors.items()}
    misses = [f"{t.title()} {100 * e:.1f}% > {100 * g:.0f}%" for t, (e, g) in errors.items() if e > g]
    if misses:
        entry["fit_misses"] = misses
    return entry


def shared_bakes(materials: dict) -> dict:
    """{LUT key: [material names]} for the paint types that several of a
    file's materials share (baked once, the others found it cached)."""
    groups = {}
    for name, m in materials.items():
        if m.get("type"):
            groups.setdefault(m["type"], []).append(name)
    return {key: names for key, names in groups.items() if len(names) > 1}


def bake_file(path, force=False, pack=False, **options) -> dict:
    """Bake one .blend file.  Returns its report entry: {"file", "status"
    ("saved", "unchanged" or "failed"), "reason" (when failed), "materials":
    {name: {"status": "baked" | "cached" | "unused" | "linked" | "failed",
    "reason", and for linked ones "library" and "baked"}}}.  Never raises."""
    path = pathlib.Path(path).resolve()
    entry = {"file": str(path), "materials": {}}
    try:
        check_blend(path)
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except (ValueError, RuntimeError) as exc:
        entry.update(status="failed", reason=str(exc).strip())
        return entry
    try:
        used = materials_to_bake(bpy.data.scenes)
    except Exception as exc:  # the file cannot be evaluated: nothing is baked or saved
        entry.update(status="failed", reason=f"cannot find the materials it uses: {type(exc).__name__}: {exc}")
        return entry
    for material in list(bpy.data.materials):
        if material.paint_lut.enabled:
            entry["materials"][_report_name(material)] = bake_one(material, used, force=force, **options)
    shared = shared_bakes(entry["materials"])
    if shared:
        entry["shared"] = shared
    baked = any(m["status"] == "baked" for m in entry["materials"].values())
    if baked or pack:
        try:
            save_atomically(path, pack=pack)
        except (OSError, RuntimeError) as exc:
            entry.update(status="failed", reason=f"cannot save {path}: {exc}")
            return entry
        entry["status"] = "saved"
    else:
        entry["status"] = "unchanged"
    if any(_failed(m) for m in entry["materials"].values()):
        entry["reason"] = "some materials failed or are not baked in their library"
    return entry


def _failed(material_entry) -> bool:
    status = material_entry["status"]
    return status == "failed" or (status == "linked" and not material_entry.get("baked"))


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
        text = ", ".join(f"{v} {k}" for k, v in sorted(counts.items())) or "no paint materials"
        lines.append(
            f"{entry['file']}: {entry['status']} ({text})" + (f": {entry['reason']}" if "reason" in entry else "")
        )
        for name, m in entry["materials"].items():
            if m["status"] in ("failed", "linked"):
                lines.append(f"  {name}: {m['status']}: {m['reason']}")
            if m.get("fit_misses"):
                lines.append(f"  {name}: fit misses its target: {', '.join(m['fit_misses'])}")
        for key, names in entry.get("shared", {}).items():
            lines.append(f"  one bake of paint type {key[:12]} shared by {', '.join(names)}")
    return "\n".join(lines)
