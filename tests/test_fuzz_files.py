"""Damaged LUT and weights files, with a fixed seed: every bit flip and every
truncation either loads exactly the data that was written or raises
lut.LUTError; never another exception.  Both readers: OpenImageIO (when
installed) and the numpy fallback (lut.lutfiles.exr)."""

import random

import numpy as np
import pytest

import lut
from lut.lutfiles import format as lutfile

SEED = 20240611
FLIPS = 160
RESOLUTION = (8, 6, 4)


def _readers():
    readers = ["fallback"]
    if lutfile._oiio() is not None:
        readers.insert(0, "openimageio")
    return readers


@pytest.fixture(params=_readers())
def reader(request, monkeypatch):
    if request.param == "fallback":
        monkeypatch.setattr(lutfile, "_oiio", lambda: None)
    return request.param


@pytest.fixture(scope="module")
def lut_bytes(tmp_path_factory):
    """A small LUT written both compressed (OpenImageIO) and not (lut.lutfiles.exr)."""
    directory = tmp_path_factory.mktemp("fuzz")
    path = lut.bake(lut.Paint(rho=(0.6, 0.3, 0.2), single=0.1, g=0.3), directory, resolution=RESOLUTION)
    table, header = lutfile.read(path)
    files = {"openimageio" if lutfile._oiio() is not None else "fallback": path.read_bytes()}
    plain = directory / "plain.exr"
    lutfile.exr.write(
        plain,
        lutfile._to_image(table),
        attributes={
            "paintlut:format": lutfile.FORMAT_VERSION,
            "paintlut:meta": header["meta_json"],
            "paintlut:key": header["key"],
            "paintlut:hash": header["hash"],
        },
    )
    files["fallback"] = plain.read_bytes()
    return files, table, header["meta"]


@pytest.fixture(scope="module")
def weights_bytes(tmp_path_factory):
    """A closure fit's weights file, as the render path writes it."""
    from lut.render import fitting

    directory = tmp_path_factory.mktemp("fuzz_weights")
    table = lut.load_lut(lut.bake(lut.Paint(rho=0.4, slope=0.3), directory, resolution=RESOLUTION))
    fit = fitting.fit_lut(table, "CYCLES", budget=3)
    path = fitting.write_fit(fit, directory / "weights.exr")
    return path.read_bytes(), fitting.read_fit(path)


def _damaged(data: bytes, rng: random.Random):
    """Single-bit flips (half of them in the header, where the metadata
    lives) and truncations at random lengths."""
    header_end = min(len(data), data.find(b"\0\0") + 2 if b"\0\0" in data else len(data), 2048)
    for i in range(FLIPS):
        damaged = bytearray(data)
        pos = rng.randrange(max(header_end, 8)) if i % 2 else rng.randrange(len(data))
        damaged[pos] ^= 1 << rng.randrange(8)
        yield f"bit flip at byte {pos}", bytes(damaged)
    for cut in sorted(rng.sample(range(len(data)), 40)):
        yield f"truncated to {cut} bytes", data[:cut]


def _loaded_or_refused(load, target, damaged, what):
    """``load(target)`` of a damaged file: what it loaded, or None when it
    raised lut.LUTError naming the file; any other exception fails the test
    (the defect this module exists for)."""
    target.write_bytes(damaged)
    try:
        return load(target)
    except lut.LUTError as exc:
        assert str(target) in str(exc), what
        return None
    except Exception as exc:
        pytest.fail(f"{what}: {type(exc).__name__}: {exc}")


def test_damaged_luts_load_identical_data_or_raise_lut_error(reader, lut_bytes, tmp_path):
    files, table, meta = lut_bytes
    target = tmp_path / "paintlut-damaged.exr"
    rng = random.Random(SEED)
    for written_by, data in files.items():
        refused = 0
        for what, damaged in _damaged(data, rng):
            what = f"{written_by} file, {what}"
            loaded = _loaded_or_refused(lut.load_lut, target, damaged, what)
            if loaded is None:
                refused += 1
                continue
            assert np.array_equal(loaded.data, table) and loaded.meta == meta, what
        assert refused > FLIPS // 2  # most damage is detected, not ignored


def test_damaged_weights_load_identical_data_or_raise_lut_error(reader, weights_bytes, tmp_path):
    from lut.render import fitting

    data, fit = weights_bytes  # ZIP-compressed when OpenImageIO wrote it: the fallback reads that too
    target = tmp_path / "paintfit-damaged.exr"
    rng = random.Random(SEED + 1)
    refused = 0
    for what, damaged in _damaged(data, rng):
        loaded = _loaded_or_refused(fitting.read_fit, target, damaged, what)
        if loaded is None:
            refused += 1
            continue
        assert np.array_equal(loaded.weights, fit.weights) and loaded.header() == fit.header(), what
    assert refused > FLIPS // 2


def test_a_weights_file_without_its_hash_is_refused(tmp_path, reader):
    path = tmp_path / "old.exr"
    lutfile.exr.write(path, np.ones((2, 3, 3), np.float32), attributes={"paintlut:closures": "('lambert',)"})
    with pytest.raises(lut.LUTError, match="no paintlut:hash"):
        lutfile.read_exr(path)


def test_bake_rebakes_a_lut_whose_metadata_is_not_utf8(reader, tmp_path):
    paint = lut.Paint(rho=0.4)
    path = lut.bake(paint, tmp_path, resolution=RESOLUTION)
    data = bytearray(path.read_bytes())
    at = data.index(b'"type":{')
    data[at + 3] = 0xFF  # one damaged byte inside the paintlut:meta text
    path.write_bytes(bytes(data))
    with pytest.raises(lut.LUTError, match=str(path.name)):
        lut.load_lut(path)
    assert lut.bake(paint, tmp_path, resolution=RESOLUTION) == path
    assert lut.load_lut(path).matches(paint)  # baked again, whole


def test_a_weights_file_of_the_previous_release_is_refused_not_misread(tmp_path, reader):
    from lut.render import fitting

    path = tmp_path / "paintfit-old.exr"
    lutfile.write_exr(path, np.ones((2, 3, 3), np.float32), {"paintlut:closures": "('lambert',)"})
    with pytest.raises(lut.LUTError, match="not a Paint LUT weights file"):
        fitting.read_fit(path)
