"""Paint LUT files: OpenEXR images written and read with OpenImageIO, or
without it by lut.exr (numpy; Blender 4.2-4.3 ship no OpenImageIO module).

Layout (format version 2).  A float32 three-channel image of width N_u and
height T · N_φd · N_θd: T tiles (meta "tiles": 1, or 3 for a dispersive
paint, one per RGB channel) of N_φd blocks of (θh, θd) stacked vertically.
Pixel (x, y) of tile t holds, in its channels, G = f · cos θi · cos θs
(``lut.table``) of the components (meta "components": facet, single,
diffuse; ``lut.baking``) at u = x / (N_u - 1),
θd = (y' mod N_θd) / (N_θd - 1) · π/2 and φd = (y' div N_θd) / (N_φd - 1) · π/2,
y' = y - t · N_φd · N_θd.  The values are data, not colour: read them as
Non-Color.

Header attributes:
  paintlut:format  the format version (int)
  paintlut:meta    JSON: paint, working space, parameterization, resolution,
                   quadrature sizes, model version
  paintlut:key     SHA-256 of the canonical meta JSON: the cache key
  paintlut:hash    SHA-256 of the meta JSON and the pixel bytes: detects a
                   file whose content was altered
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import pathlib
import tempfile

import numpy as np

from . import exr

FORMAT_VERSION = 2
PARAMETERIZATION = "rusinkiewicz(theta_h=pi/2*u^2, theta_d, phi_d in [0, pi/2]); G = f cos(theta_i) cos(theta_s)"


class LUTError(ValueError):
    """A LUT file that cannot be used: missing, unreadable or truncated, of
    another format version, or whose content does not match its hash."""


def _oiio():
    """The OpenImageIO module, or None: then ``lut.exr`` (numpy) reads and
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
    compressed; or uncompressed through lut.exr)."""
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


def _read_image(path, keys=(), what="file"):
    """(pixels (height, width, channels) float32, {key: attribute or None})
    of an EXR file; raises LUTError when it cannot be read."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise LUTError(f"{path}: no such {what}")
    oiio = _oiio()
    if oiio is None:
        try:
            pixels, _, attrs = exr.read(path)
        except (exr.EXRError, OSError) as exc:
            raise LUTError(f"{path}: not a readable EXR image (truncated or corrupt?): {exc}") from None
        return pixels, {key: attrs.get(key) for key in keys}
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise LUTError(f"{path}: not a readable EXR image (truncated or corrupt?): {oiio.geterror()}")
    try:
        spec = inp.spec()
        attrs = {key: spec.getattribute(key) for key in keys}
        pixels = inp.read_image(oiio.FLOAT)
    finally:
        inp.close()
    if pixels is None or np.ndim(pixels) != 3:
        raise LUTError(f"{path}: pixel data cannot be read (truncated file?): {oiio.geterror()}")
    return np.asarray(pixels, dtype=np.float32), attrs


def canonical_json(meta: dict) -> str:
    return json.dumps(meta, sort_keys=True, separators=(",", ":"))


def cache_key(meta: dict) -> str:
    return hashlib.sha256(canonical_json(meta).encode()).hexdigest()


def content_hash(meta_json: str, pixels: np.ndarray) -> str:
    h = hashlib.sha256(meta_json.encode())
    h.update(np.ascontiguousarray(pixels, dtype="<f4").tobytes())
    return h.hexdigest()


def _to_image(table: np.ndarray) -> np.ndarray:
    """(tiles, N_φd, N_θd, N_u, 3) or (N_φd, N_θd, N_u, 3) -> (height, N_u, 3)."""
    n_u, c = table.shape[-2:]
    return np.ascontiguousarray(table.reshape(-1, n_u, c), dtype=np.float32)


@contextlib.contextmanager
def atomic_target(path):
    """Write a file atomically: yields a temporary path in the same directory
    (same suffix, so writers that go by the extension work) that is renamed
    onto ``path`` when the block succeeds and removed when it fails, so an
    interrupted write never leaves a partial file and never loses the old one."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=f".partial{path.suffix}")
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)


def atomic_write_bytes(path, data: bytes) -> pathlib.Path:
    """Write bytes to ``path`` atomically (``atomic_target``)."""
    with atomic_target(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return pathlib.Path(path)


def write_exr(path, image: np.ndarray, attributes: dict) -> pathlib.Path:
    """Write a float32 (height, width, 3) image with string/int attributes
    atomically: to a temporary file in the same directory, renamed into
    place, so an interrupted write never leaves a partial file under ``path``."""
    path = pathlib.Path(path)
    image = np.ascontiguousarray(image, dtype=np.float32)
    with atomic_target(path) as tmp:
        _write_image(tmp, image, attributes)
    return path


def write(path, table: np.ndarray, meta: dict) -> pathlib.Path:
    """Write a LUT table (tiles, N_φd, N_θd, N_u, 3) and its meta atomically."""
    image = _to_image(table)
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
    if int(version) != FORMAT_VERSION:
        raise LUTError(f"{path}: LUT format version {version}; this version of Paint LUT reads {FORMAT_VERSION}")
    meta_json = attrs["paintlut:meta"]
    try:
        meta = json.loads(meta_json)
    except (TypeError, ValueError):
        raise LUTError(f"{path}: its paintlut:meta is not JSON (altered file)") from None
    header = {
        "meta": meta,
        "meta_json": meta_json,
        "key": attrs["paintlut:key"],
        "hash": attrs["paintlut:hash"],
        "size": (pixels.shape[1], pixels.shape[0], pixels.shape[2]),
    }
    return pixels, header


def read_exr(path) -> np.ndarray:
    """The float pixels (height, width, channels) of any EXR image, finite
    values required (closure weights files); raises LUTError."""
    pixels, _ = _read_image(path)
    if not np.all(np.isfinite(pixels)):
        raise LUTError(f"{path}: pixel values are not finite")
    return pixels


def read_header(path) -> dict:
    """The header of a LUT file (checks the format version, not the pixels):
    meta, meta_json, key, hash and size (width, height, channels)."""
    return _load(path)[1]


def read(path):
    """(table (tiles, N_φd, N_θd, N_u, 3), header) of a LUT file, verified
    against its content hash."""
    pixels, header = _load(path)
    meta = header["meta"]
    if header["key"] != cache_key(meta):
        raise LUTError(f"{path}: header key does not match its meta (altered file)")
    if header["hash"] != content_hash(header["meta_json"], pixels):
        raise LUTError(f"{path}: content does not match its hash (altered or damaged file)")
    n_u, n_d, n_p = meta["resolution"]
    tiles = meta.get("tiles", 1)
    if pixels.shape != (tiles * n_p * n_d, n_u, 3):
        raise LUTError(f"{path}: image size {pixels.shape} does not match resolution {meta['resolution']}")
    return pixels.reshape(tiles, n_p, n_d, n_u, 3), header
