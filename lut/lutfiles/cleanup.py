"""Removing the files no material uses any more from a LUT directory.

``clean(directory, keep)`` removes the LUT files (``paintlut-<key>.exr``)
not in ``keep``, the closure weights files (``paintfit-<target>[-f<version>]-<key>.exr``,
e.g. ``paintfit-cycles-f6-…``, ``paintfit-eevee-…``) of the LUTs it removes or that have no LUT
kept, and the temporary files that interrupted writes left behind.  Nothing
else in the directory is touched, and nothing outside it."""

from __future__ import annotations

import pathlib
import re

from . import files

_LUT = re.compile(r"^paintlut-(?P<key>[0-9a-f]{8,64})\.exr$")
_WEIGHTS = re.compile(r"^paintfit-(?:[a-z0-9]+-)*(?P<key>[0-9a-f]{8,64})\.exr$")


def file_key(path) -> str | None:
    """The key a LUT or weights file's name gives (``paintlut-<key>.exr``,
    ``paintfit-...-<key>.exr``), or None for a name of another form."""
    name = pathlib.Path(path).name
    match = _LUT.match(name) or _WEIGHTS.match(name)
    return match["key"] if match else None


def unused_files(directory, keep) -> list[pathlib.Path]:
    """The LUT and weights files in ``directory`` that ``clean`` removes:
    those whose key (the hash in the name) is not the key of a file in
    ``keep`` (LUT or weights paths, anywhere)."""
    directory = pathlib.Path(directory)
    if not directory.is_dir():
        raise ValueError(f"{directory}: no such directory")
    if isinstance(keep, (str, pathlib.Path)):
        raise ValueError("keep must be a list of file paths, not one path")
    kept = set()
    for path in keep:
        key = file_key(path)
        if key is None:
            raise ValueError(f"keep: {str(path)!r} is not a LUT (paintlut-<key>.exr) or weights (paintfit-...) file")
        kept.add(key)
    return sorted(
        path
        for path in directory.iterdir()
        if path.is_file() and file_key(path) is not None and file_key(path) not in kept
    )


def clean(directory, keep, dry_run=False) -> list[pathlib.Path]:
    """Remove from ``directory`` the LUTs and weights that are not kept
    (``unused_files``) and the stale temporary files of interrupted writes;
    returns what was (with ``dry_run``: would be) removed."""
    unused = unused_files(directory, keep)
    if dry_run:
        return unused + [p for p in sorted(pathlib.Path(directory).glob(".*.partial*")) if files.is_stale_partial(p)]
    removed = []
    for path in unused:
        try:
            path.unlink()
        except FileNotFoundError:
            continue
        removed.append(path)
    return removed + files.remove_stale_partials(directory)
