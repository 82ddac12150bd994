"""Headless batch baking of .blend files (for farms; scripts/batch_bake.py).

One file at a time: open it, bake the paint materials its scenes' objects use
(``api.bake_materials``: unused ones are skipped, up-to-date ones cached),
and save it atomically when anything was baked.  Every failure is reported
per item with its reason and never stops the others:

* a file that is missing or not a .blend fails and is never written;
* a material whose paint is invalid fails, keeps its previous state, and the
  file is still saved with the other materials' bakes;
* a corrupted or missing LUT or weights file is rebaked.

Saving writes a temporary file next to the .blend and renames it into place,
so an interrupted run never leaves a half-written .blend (no .blend1 backup
either: the old file is replaced only by a complete new one)."""

from __future__ import annotations

import os
import pathlib

import bpy

from lut import lutfile

from . import api

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


def bake_file(path, force=False, pack=False, **options) -> dict:
    """Bake one .blend file.  Returns its report entry: {"file", "status"
    ("saved", "unchanged" or "failed"), "reason" (when failed), "materials":
    {name: {"status": "baked" | "cached" | "unused" | "failed", "reason"}}}."""
    path = pathlib.Path(path).resolve()
    entry = {"file": str(path), "materials": {}}
    try:
        check_blend(path)
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except (ValueError, RuntimeError) as exc:
        entry.update(status="failed", reason=str(exc).strip())
        return entry
    status = api.bake_materials(api.used_materials(bpy.data.scenes), force=force, **options)
    for name, text in status.items():
        kind, _, reason = text.partition(": ")
        entry["materials"][name] = {"status": kind, **({"reason": reason} if reason else {})}
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
    if any(m["status"] == "failed" for m in entry["materials"].values()):
        entry["reason"] = "some materials failed"
    return entry


def failed(entries) -> bool:
    """Whether any file or material of a report failed."""
    return any(
        e["status"] == "failed" or any(m["status"] == "failed" for m in e["materials"].values()) for e in entries
    )


def summary(entries) -> str:
    """One line per file (its status and material counts), one per failed material."""
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
            if m["status"] == "failed":
                lines.append(f"  {name}: failed: {m['reason']}")
    return "\n".join(lines)
