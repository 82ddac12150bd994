"""Paint LUT files: OpenEXR images written and read with OpenImageIO, or
without it by lut.lutfiles.exr (numpy; Blender 4.2-4.3 ship no OpenImageIO module).

Layout (format version 2).  A float32 three-channel image of width N_u and
height T · N_φd · N_θd: T tiles (meta "tiles": 1, or 3 for a dispersive
paint, one per RGB channel) of N_φd blocks of (θh, θd) stacked vertically.
Pixel (x, y) of tile t holds, in its channels, G = f · cos θi · cos θs
(``lut.lutfiles.table``) of the components (meta "components": facet, single,
diffuse; ``lut.lutfiles.baking``) at u = x / (N_u - 1),
θd = (y' mod N_θd) / (N_θd - 1) · π/2 and φd = (y' div N_θd) / (N_φd - 1) · π/2,
y' = y - t · N_φd · N_θd.  The values are data, not colour: read them as
Non-Color.

Header attributes:
  paintlut:format  the format version (int)
  paintlut:meta    JSON: paint, working space, parameterization, resolution,
                   quadrature sizes, model version
  paintlut:key     SHA-256 of the canonical meta JSON without its derived
                   fields (``DERIVED_FIELDS``: r̄): the cache key
  paintlut:hash    SHA-256 of the meta JSON and the pixel bytes: detects a
                   file whose content was altered

Other images written by ``write_exr`` (closure weights) carry a
``paintlut:hash`` of their other ``paintlut:`` attributes and pixels.  Every
malformed file, whatever the damage, raises LUTError naming it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import pathlib
import sys
import tempfile
import threading

import numpy as np

from . import exr

# Re-exported for callers of earlier releases, which wrote through lutfile.
from .files import atomic_target, atomic_write_bytes  # noqa: F401

FORMAT_VERSION = 2
PARAMETERIZATION = "rusinkiewicz(theta_h=pi/2*u^2, theta_d, phi_d in [0, pi/2]); G = f cos(theta_i) cos(theta_s)"


class LUTError(ValueError):
    """A LUT file that cannot be used: missing, unreadable or truncated, of
    another format version, or whose content does not match its hash."""


def _oiio():
    """The OpenImageIO module, or None: then ``lut.lutfiles.exr`` (numpy) reads and
    writes the files.  Inside Blender 4.4+ the add-on layer makes Blender's
    bundled module importable first (bpy.utils.expose_bundled_modules());
    Blender 4.2-4.3 have none.  ``lut`` itself never imports bpy."""
    try:
        import OpenImageIO as oiio
    except ImportError:
        return None
    return oiio


def _write_image(path, image, attributes):
    """Write an RGB float image with attributes (OpenImageIO, ZIP
    compressed; or uncompressed through lut.lutfiles.exr)."""
    oiio = _oiio()
    if oiio is None:
        exr.write(path, image, ("R", "G", "B"), attributes)
        return
    spec = oiio.ImageSpec(image.shape[1], image.shape[0], image.shape[2], oiio.FLOAT)
    spec.channelnames = ("R", "G", "B")
    spec.attribute("compression", "zip")
    spec.attribute("oiio:ColorSpace", "Non-Color")
    for key, value in attributes.items():
        spec.attribute(key, value)
    out = oiio.ImageOutput.create(path)
    if out is None or not out.open(path, spec):
        raise OSError(f"cannot write {path}: {oiio.geterror()}")
    ok = out.write_image(image)
    out.close()
    if not ok:
        raise OSError(f"cannot write {path}: {oiio.geterror()}")


def _read_image(path, keys=(), what="file", prefix=None):
    """(pixels (height, width, channels) float32, {key: attribute or None})
    of an EXR file, with every attribute whose name starts with ``prefix``
    added; raises LUTError, naming the file, for anything that cannot be read."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise LUTError(f"{path}: no such {what}")
    try:
        return _read_any(path, keys, prefix)
    except LUTError:
        raise
    except OSError as exc:
        raise LUTError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    except Exception as exc:  # a damaged file must never surface as another error
        raise LUTError(f"{path}: not a readable EXR image (damaged file?): {type(exc).__name__}: {exc}") from None


def _read_any(path, keys, prefix):
    oiio = _oiio()
    if oiio is None:
        try:
            pixels, _, attrs = exr.read(path)
        except exr.EXRError as exc:
            raise LUTError(f"not a readable EXR image (truncated or corrupt?): {exc}") from None  # exc names the file
        found = {key: attrs.get(key) for key in keys}
        if prefix:
            found.update((k, v) for k, v in attrs.items() if k.startswith(prefix))
        return pixels, found
    with _stderr_kept() as printed:
        inp = oiio.ImageInput.open(str(path))
        if inp is None:
            raise LUTError(f"{path}: not a readable EXR image (truncated or corrupt?): {oiio.geterror()}")
        try:
            spec = inp.spec()
            attrs = {key: _attribute(spec, key, path) for key in keys}
            if prefix:
                names = [p.name for p in spec.extra_attribs if p.name.startswith(prefix)]
                attrs.update((name, _attribute(spec, name, path)) for name in names)
            pixels = inp.read_image(oiio.FLOAT)
            error = inp.geterror()
        finally:
            inp.close()
    if pixels is None or np.ndim(pixels) != 3 or error:
        raise LUTError(f"{path}: pixel data cannot be read (truncated file?): {error or oiio.geterror()}")
    if printed and sys.stderr is not None:  # a file that reads whole: what the libraries printed is news
        sys.stderr.write(printed[0])
    return np.asarray(pixels, dtype=np.float32), attrs


@contextlib.contextmanager
def _stderr_kept():
    """Hold what native code prints on file descriptor 2 while a file is
    read: OpenEXR's core prints a raw line per damaged chunk (dozens for one
    truncated file) before OpenImageIO reports the one error that the
    ``LUTError`` gives.  Yields a list that holds the text after the block
    (passed on by the caller when the read succeeds).  Where descriptor 2
    cannot be redirected, nothing is held."""
    held = []
    with _STDERR_LOCK:  # one redirection at a time: threads read files too
        try:
            if sys.stderr is not None:
                sys.stderr.flush()
            sink = tempfile.TemporaryFile()
        except (OSError, ValueError):
            yield held  # nothing to flush into, or no temporary file: not held
            return
        with sink:
            try:
                saved = os.dup(2)
            except OSError:
                yield held
                return
            os.dup2(sink.fileno(), 2)
            try:
                yield held
            finally:
                os.dup2(saved, 2)
                os.close(saved)
            sink.seek(0)
            printed = sink.read().decode(errors="replace")
            if printed:
                held.append(printed)


_STDERR_LOCK = threading.RLock()


def _attribute(spec, key, path):
    try:
        return spec.getattribute(key)
    except UnicodeDecodeError:
        raise LUTError(f"{path}: its attribute {key} is not UTF-8 text (damaged file)") from None


def canonical_json(meta: dict) -> str:
    return json.dumps(meta, sort_keys=True, separators=(",", ":"))


#: Meta fields derived from the others: recorded in a file (and covered by
#: its content hash) but not part of its key.  Computed by numpy, their last
#: bits differ between numpy versions (r̄ reads 0.5959642684316706 under
#: numpy 1.26 and 0.5959642684316686 under 2.x), and one paint type must
#: have one key on every machine of a farm.
DERIVED_FIELDS = ("internal_reflectance",)


def cache_key(meta: dict) -> str:
    """The key of a bake's ``meta``: a hash of what determines its content
    (everything but ``DERIVED_FIELDS``)."""
    return _meta_hash({name: value for name, value in meta.items() if name not in DERIVED_FIELDS})


def _meta_hash(meta: dict) -> str:
    """SHA-256 of a meta's canonical JSON (the key of files written before
    ``DERIVED_FIELDS`` were left out of keys: the whole meta)."""
    return hashlib.sha256(canonical_json(meta).encode()).hexdigest()


def content_hash(meta_json: str, pixels: np.ndarray) -> str:
    h = hashlib.sha256(meta_json.encode())
    h.update(np.ascontiguousarray(pixels, dtype="<f4").tobytes())
    return h.hexdigest()


def _to_image(table: np.ndarray) -> np.ndarray:
    """(tiles, N_φd, N_θd, N_u, 3) or (N_φd, N_θd, N_u, 3) -> (height, N_u, 3)."""
    n_u, c = table.shape[-2:]
    return np.ascontiguousarray(table.reshape(-1, n_u, c), dtype=np.float32)


def write_exr(path, image: np.ndarray, attributes: dict) -> pathlib.Path:
    """Write a float32 (height, width, 3) image with string/int attributes
    atomically: to a temporary file in the same directory, renamed into
    place, so an interrupted write never leaves a partial file under ``path``.
    Unless given, a ``paintlut:hash`` of the attributes and pixels is added,
    which ``read_exr`` verifies."""
    path = pathlib.Path(path)
    image = np.ascontiguousarray(image, dtype=np.float32)
    if "paintlut:hash" not in attributes:
        attributes = {**attributes, "paintlut:hash": content_hash(canonical_json(attributes), image)}
    with atomic_target(path) as tmp:
        _write_image(tmp, image, attributes)
    return path


def write(path, table: np.ndarray, meta: dict) -> pathlib.Path:
    """Write a LUT table (tiles, N_φd, N_θd, N_u, 3) and its meta atomically.
    A table with values that are not finite (a paint beyond float32's range,
    e.g. a facet lobe far narrower than the table) is refused: ValueError."""
    image = _to_image(table)
    if not np.all(np.isfinite(image)):
        raise ValueError(
            "the baked LUT has values that are not finite (beyond float32's range): the paint's parameters are "
            "outside what a LUT can hold (for example a slope far below 0.001; use 0 for a smooth surface)"
        )
    meta_json = canonical_json(meta)
    return write_exr(
        path,
        image,
        {
            "paintlut:format": FORMAT_VERSION,
            "paintlut:meta": meta_json,
            "paintlut:key": cache_key(meta),
            "paintlut:hash": content_hash(meta_json, image),
        },
    )


_KEYS = ("paintlut:format", "paintlut:meta", "paintlut:key", "paintlut:hash")


def _load(path):
    """(pixels, header) of a LUT file; checks the format version."""
    pixels, attrs = _read_image(path, _KEYS, "LUT file")
    version = attrs["paintlut:format"]
    if version is None:
        raise LUTError(f"{path}: not a Paint LUT (no paintlut:format attribute)")
    if not isinstance(version, int) or isinstance(version, bool):
        raise LUTError(f"{path}: its paintlut:format is not a whole number (altered file)")
    if version != FORMAT_VERSION:
        raise LUTError(f"{path}: LUT format version {version}; this version of Paint LUT reads {FORMAT_VERSION}")
    meta_json = attrs["paintlut:meta"]
    try:
        meta = json.loads(meta_json)
    except (TypeError, ValueError, RecursionError):
        raise LUTError(f"{path}: its paintlut:meta is not JSON (altered file)") from None
    if not isinstance(meta, dict) or not all(isinstance(attrs[k], str) for k in ("paintlut:key", "paintlut:hash")):
        raise LUTError(f"{path}: its paintlut:meta, key or hash is malformed (altered file)")
    header = {
        "meta": meta,
        "meta_json": meta_json,
        "key": attrs["paintlut:key"],
        "hash": attrs["paintlut:hash"],
        "size": (pixels.shape[1], pixels.shape[0], pixels.shape[2]),
    }
    return pixels, header


def read_exr(path) -> np.ndarray:
    """The float pixels (height, width, channels) of an EXR image written by
    ``write_exr`` (closure weights files), verified against its
    ``paintlut:hash`` and finite; raises LUTError."""
    return read_exr_attributes(path)[0]


def read_exr_attributes(path, what="file", expect=None):
    """(pixels, {name: value} of its ``paintlut:`` attributes but the hash)
    of an EXR image written by ``write_exr``, verified as ``read_exr``
    verifies it; raises LUTError naming the file (``what`` it is), first
    where an attribute of ``expect`` ({name: value}) has another value."""
    pixels, attrs = _read_image(path, ("paintlut:hash",), what, prefix="paintlut:")
    for name, value in (expect or {}).items():
        if attrs.get(name) != value:
            raise LUTError(f"{path}: not a {what} of this version (its {name} is {attrs.get(name)!r}, not {value!r})")
    stored = attrs.pop("paintlut:hash")
    if not isinstance(stored, str):
        raise LUTError(f"{path}: no paintlut:hash (written by an older version, or altered): bake it again")
    if stored != content_hash(canonical_json(attrs), pixels):
        raise LUTError(f"{path}: content does not match its hash (altered or damaged file)")
    if not np.all(np.isfinite(pixels)):
        raise LUTError(f"{path}: pixel values are not finite")
    return pixels, attrs


def read_header(path) -> dict:
    """The header of a LUT file (checks the format version, not the pixels):
    meta, meta_json, key, hash and size (width, height, channels)."""
    return _load(path)[1]


def read(path):
    """(table (tiles, N_φd, N_θd, N_u, 3), header) of a LUT file, verified
    against its content hash."""
    pixels, header = _load(path)
    meta = header["meta"]
    # A file written before DERIVED_FIELDS were left out of keys has the
    # key of its whole meta: still whole, and read (a bake names its new
    # files by the new key, so such a file is baked again once, not lost).
    if header["key"] not in (cache_key(meta), _meta_hash(meta)):
        raise LUTError(f"{path}: header key does not match its meta (altered file)")
    if header["hash"] != content_hash(header["meta_json"], pixels):
        raise LUTError(f"{path}: content does not match its hash (altered or damaged file)")
    resolution = meta.get("resolution")
    if (
        not isinstance(resolution, list)
        or len(resolution) != 3
        or not all(isinstance(r, int) and not isinstance(r, bool) and r >= 2 for r in resolution)
    ):
        raise LUTError(f"{path}: its meta has no valid resolution (altered file)")
    tiles = meta.get("tiles", 1)
    if not isinstance(tiles, int) or isinstance(tiles, bool) or tiles not in (1, 3):
        raise LUTError(f"{path}: its meta has no valid tile count (altered file)")
    n_u, n_d, n_p = resolution
    if pixels.shape != (tiles * n_p * n_d, n_u, 3):
        raise LUTError(f"{path}: image size {pixels.shape} does not match resolution {resolution}")
    return pixels.reshape(tiles, n_p, n_d, n_u, 3), header
