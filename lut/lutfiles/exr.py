"""A minimal OpenEXR reader and writer in numpy, for Pythons without the
OpenImageIO module (Blender 4.2 and 4.3 do not ship it; 4.4+ do).

Writes single-part scanline images of 32-bit float channels, uncompressed,
with string and int header attributes; reads those and the ZIP/ZIPS
compressed float images OpenImageIO writes by default.  Layout from the
OpenEXR file-layout specification (openexr.com, "OpenEXR File Layout"):
magic, version, attributes (name, type, size, value) up to an empty name,
the scanline offset table, then chunks of (y, size, data) with each
scanline's channels stored one after another in alphabetical order.
ZIP chunks are zlib streams of the scanlines' bytes split into even and odd
bytes and delta-encoded ("predictor")."""

from __future__ import annotations

import struct
import zlib

import numpy as np

MAGIC = 20000630
_NO_COMPRESSION, _ZIPS, _ZIP = 0, 2, 3
_LINES = {_NO_COMPRESSION: 1, _ZIPS: 1, _ZIP: 16}
_FLOAT = 2


class EXRError(ValueError):
    """Not an EXR image this module reads."""


def _attr(name: str, kind: str, value: bytes) -> bytes:
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def write(path, image: np.ndarray, names=("R", "G", "B"), attributes=None) -> None:
    """Write a float32 (height, width, channels) image uncompressed."""
    image = np.ascontiguousarray(image, dtype="<f4")
    height, width, channels = image.shape
    if len(names) != channels:
        raise ValueError(f"names must give one name per channel ({channels}), got {names!r}")
    order = sorted(range(channels), key=lambda c: names[c])
    chlist = b"".join(names[c].encode() + b"\0" + struct.pack("<iB3xii", _FLOAT, 0, 1, 1) for c in order) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = [
        _attr("channels", "chlist", chlist),
        _attr("compression", "compression", bytes([_NO_COMPRESSION])),
        _attr("dataWindow", "box2i", box),
        _attr("displayWindow", "box2i", box),
        _attr("lineOrder", "lineOrder", b"\0"),
        _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        _attr("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]
    for key, value in (attributes or {}).items():
        if isinstance(value, bool) or not isinstance(value, (int, str)):
            raise ValueError(f"attribute {key!r} must be a string or an int, got {value!r}")
        header.append(
            _attr(key, "int", struct.pack("<i", value))
            if isinstance(value, int)
            else _attr(key, "string", value.encode())
        )
    head = struct.pack("<ii", MAGIC, 2) + b"".join(header) + b"\0"
    line_bytes = width * channels * 4
    start = len(head) + 8 * height
    offsets = struct.pack(f"<{height}Q", *(start + y * (8 + line_bytes) for y in range(height)))
    planar = image[:, :, order].transpose(0, 2, 1)  # (height, channel, width)
    with open(path, "wb") as fh:
        fh.write(head + offsets)
        for y in range(height):
            fh.write(struct.pack("<ii", y, line_bytes) + planar[y].tobytes())


def _parse_attr(kind, value):
    if kind == "string":
        try:
            return value.decode("utf-8")
        except UnicodeDecodeError:
            raise EXRError("a string attribute is not UTF-8") from None
    if kind == "int":
        return struct.unpack("<i", value)[0]
    if kind == "float":
        return struct.unpack("<f", value)[0]
    if kind == "box2i":
        return struct.unpack("<iiii", value)
    if kind in ("compression", "lineOrder"):
        return value[0]
    if kind == "chlist":
        channels, at = [], 0
        while value[at] != 0:
            end = value.index(b"\0", at)
            pixel_type = struct.unpack_from("<i", value, end + 1)[0]
            channels.append((value[at:end].decode(), pixel_type))
            at = end + 17
        return channels
    return value


def read(path):
    """(pixels (height, width, channels) float32 in the order R, G, B, A then
    others, channel names, attributes) of an EXR file; raises EXRError for
    anything that is not a whole, well-formed image of the kind ``write``
    makes (or OpenImageIO's ZIP/ZIPS float images)."""
    with open(path, "rb") as fh:
        data = fh.read()
    try:
        return _decode(data)
    except EXRError as exc:
        raise EXRError(f"{path}: {exc}") from None
    except (struct.error, IndexError, KeyError, TypeError, ValueError, OverflowError, zlib.error) as exc:
        raise EXRError(f"{path}: damaged or truncated EXR file ({type(exc).__name__}: {exc})") from None


def _decode(data: bytes):
    magic, version = struct.unpack_from("<ii", data, 0)
    if magic != MAGIC:
        raise EXRError("not an EXR file")
    if version & 0x1A00:  # tiled, deep or multi-part (long names are fine)
        raise EXRError("only single-part scanline EXR files are read without OpenImageIO")
    attrs, at = {}, 8
    while data[at] != 0:
        name_end = data.index(b"\0", at)
        kind_end = data.index(b"\0", name_end + 1)
        size = struct.unpack_from("<i", data, kind_end + 1)[0]
        if size < 0 or kind_end + 5 + size > len(data):
            raise EXRError("an attribute runs past the end of the file")
        value = data[kind_end + 5 : kind_end + 5 + size]
        attrs[data[at:name_end].decode()] = _parse_attr(data[name_end + 1 : kind_end].decode(), value)
        at = kind_end + 5 + size
    at += 1
    x0, y0, x1, y1 = attrs["dataWindow"]
    width, height = x1 - x0 + 1, y1 - y0 + 1
    channels = attrs["channels"]
    compression = attrs["compression"]
    if compression not in _LINES or any(t != _FLOAT for _, t in channels):
        raise EXRError("only 32-bit float, uncompressed or ZIP EXR files are read without OpenImageIO")
    if width < 1 or height < 1 or not channels:
        raise EXRError(f"empty image ({width}x{height}, {len(channels)} channels)")
    lines = _LINES[compression]
    chunks = -(-height // lines)
    if at + 8 * chunks > len(data):
        raise EXRError("truncated scanline offset table")
    offsets = struct.unpack_from(f"<{chunks}Q", data, at)
    line_bytes = len(channels) * width * 4
    rows = [None] * chunks
    for offset in offsets:
        if offset > len(data) - 8:
            raise EXRError("a scanline offset points past the end of the file")
        y, size = struct.unpack_from("<ii", data, offset)
        index, remainder = divmod(y - y0, lines)
        if remainder or not 0 <= index < chunks or rows[index] is not None:
            raise EXRError(f"unexpected scanline {y}")
        if size < 0 or offset + 8 + size > len(data):
            raise EXRError("truncated pixel data")
        block = data[offset + 8 : offset + 8 + size]
        n = min(lines, y1 - y + 1)
        raw = n * line_bytes
        if compression != _NO_COMPRESSION and size < raw:
            block = _unzip(block, raw)
        if len(block) != raw:
            raise EXRError("truncated pixel data")
        rows[index] = np.frombuffer(block, dtype="<f4").reshape(n, len(channels), width)
    planar = np.concatenate(rows)  # (height, channel, width), channels sorted by name
    names = [name for name, _ in channels]
    rank = {"R": 0, "G": 1, "B": 2, "A": 3}
    order = sorted(range(len(names)), key=lambda c: (rank.get(names[c], 4), names[c]))
    pixels = np.ascontiguousarray(planar.transpose(0, 2, 1)[:, :, order], dtype=np.float32)
    return pixels, [names[c] for c in order], attrs


def _unzip(block: bytes, size: int) -> bytes:
    """Undo OpenEXR's ZIP: inflate (to at most ``size`` bytes: a damaged
    stream cannot claim unbounded memory), undo the byte delta, re-interleave
    the two halves."""
    inflate = zlib.decompressobj()
    t = inflate.decompress(block, size)
    if inflate.unconsumed_tail or not inflate.eof:
        raise EXRError("damaged compressed pixel data")
    t = np.frombuffer(t, dtype=np.uint8)
    t = np.cumsum(t.astype(np.int64) - 128 * (np.arange(t.size) > 0)) & 0xFF
    t = t.astype(np.uint8)
    half = (t.size + 1) // 2
    out = np.empty(t.size, dtype=np.uint8)
    out[0::2], out[1::2] = t[:half], t[half:]
    return out.tobytes()
