"""lut.bake and lut.load_lut: paint types baked into colour-free components,
accuracy, metadata, cache, and files that are damaged, foreign or
interrupted."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import lut
from lut import models
from lut.lutfiles import format as lutfile
from lut.lutfiles import table

RNG = np.random.default_rng(9)

PAINTS = {
    "smooth": lut.Paint(n=1.5, rho=(0.8, 0.45, 0.15), single=(0.05, 0.2, 0.3), g=0.3),
    "satin": lut.Paint(n=1.5, rho=(0.8, 0.45, 0.15), single=(0.05, 0.2, 0.3), g=0.3, slope=0.25),
    "matte": lut.Paint(
        n=1.5, rho=(0.8, 0.45, 0.15), single=(0.05, 0.2, 0.3), g=0.3, slope=2.0, distribution="exponential"
    ),
}


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    directory = tmp_path_factory.mktemp("luts")
    return {name: lut.bake(p, directory) for name, p in PAINTS.items()}


@pytest.mark.parametrize("name", list(PAINTS))
def test_lut_matches_the_model_within_one_percent(baked, name):
    """cos-weighted relative RMS over θi, θs <= 80° and all azimuths."""
    paint = PAINTS[name]
    ti = np.radians(np.linspace(0.0, 80.0, 33))
    tig, tsg, psg = np.meshgrid(ti, ti, np.linspace(-np.pi, np.pi, 40), indexing="ij")
    model = paint.brdf(tig, tsg, psg)
    got = lut.load_lut(baked[name]).evaluate(tig, tsg, psg, paint)
    w = np.cos(tig)[..., None]
    err = np.sqrt(np.sum(((got - model) * w) ** 2) / np.sum((model * w) ** 2))
    assert err < 0.01
    assert got.shape == tig.shape + (3,)
    assert np.all(lut.load_lut(baked[name]).evaluate(1.6, 0.3, 0.0, paint) == 0)  # below the horizon


def test_components_recombine_into_the_model_exactly():
    """Paint.brdf = Σ_c amplitudes · components, for RGB, spectral and
    dispersive paints, smooth and rough."""
    rng = np.random.default_rng(4)
    angles = rng.uniform(0, 1.45, 200), rng.uniform(0, 1.45, 200), rng.uniform(-np.pi, np.pi, 200)
    paints = [
        lut.Paint(rho=(0.8, 0.3, 0.05), single=(0.1, 0.2, 0.0), g=-0.4),
        lut.Paint(rho=0.3, single=0.2, slope=0.4, distribution="exponential", facet=0.7),
        lut.preset("glossy_red"),
        lut.Paint(n=(1.49, 0.006), rho="ColorChecker N Ohta/red", single=0.1, slope=0.2),
    ]
    for paint in paints:
        comps, amps = paint.components(*angles), paint.amplitudes()
        got = np.einsum("...hc,hc->...h", np.broadcast_to(comps, comps.shape[:-2] + (3, 3)), amps)
        np.testing.assert_allclose(got, paint.brdf(*angles), rtol=1e-12, atol=1e-15)


def test_every_colour_of_a_type_shares_one_lut(baked, tmp_path):
    """The cache key has no colours: another colour (or facet weight) of a
    baked type is a cache hit and evaluates to that paint; another type is
    another file."""
    satin = PAINTS["satin"]
    recoloured = lut.Paint(**{**satin.__dict__, "rho": (0.1, 0.6, 0.9), "single": 0.0, "facet": 0.5})
    assert lut.lut_path(recoloured, baked["satin"].parent) == baked["satin"]
    table_ = lut.load_lut(baked["satin"])
    ti, ts, ps = np.radians([10.0, 40.0, 70.0]), np.radians([30.0, 50.0, 20.0]), np.array([0.5, 2.0, 3.0])
    np.testing.assert_allclose(table_.evaluate(ti, ts, ps, recoloured), recoloured.brdf(ti, ts, ps), rtol=0.02)
    other = lut.Paint(**{**satin.__dict__, "g": 0.31})
    assert lut.lut_path(other, baked["satin"].parent) != baked["satin"]
    with pytest.raises(ValueError, match="not of this LUT's type"):
        table_.evaluate(ti, ts, ps, other)


def test_one_paint_type_has_one_key_on_every_machine(tmp_path):
    """The key hashes what determines a LUT, not what numpy derives from it:
    r̄ differing in its last bits (numpy 1.26 against 2.x) and a slope of
    -0.0 against 0.0 (equal paints) give the same file name."""
    from lut.lutfiles import baking

    paint = PAINTS["satin"]
    meta = baking.describe(paint)
    nudged = {**meta, "internal_reflectance": meta["internal_reflectance"] * (1 + 3e-15)}
    assert nudged != meta and lutfile.cache_key(nudged) == lutfile.cache_key(meta)
    assert lutfile.cache_key({**meta, "type": {**meta["type"], "n": 1.6}}) != lutfile.cache_key(meta)
    smooth = dict(n=1.5, rho=(0.2, 0.3, 0.4), g=-0.0)
    assert lut.Paint(slope=-0.0, **smooth) == lut.Paint(slope=0.0, **smooth)
    assert baking.lut_path(lut.Paint(slope=-0.0, **smooth), tmp_path) == baking.lut_path(
        lut.Paint(slope=0.0, g=0.0, n=1.5, rho=(0.2, 0.3, 0.4)), tmp_path
    )


def test_header_describes_the_bake(baked):
    header = lutfile.read_header(baked["satin"])
    meta = header["meta"]
    assert meta["format"] == lutfile.FORMAT_VERSION
    assert meta["resolution"] == list(table.DEFAULT_RESOLUTION)
    assert meta["type"] == {"n": 1.5, "g": 0.3, "slope": 0.25, "distribution": "gaussian"}  # no colour
    assert meta["components"] == ["facet", "single", "diffuse"] and meta["tiles"] == 1
    assert meta["internal_reflectance"] == pytest.approx(PAINTS["satin"].internal_reflectance())
    assert meta["single_nodes"] == [3, 4] and meta["diffuse_nodes"] == [16, 16]
    assert header["key"] == lutfile.cache_key(meta) and len(header["hash"]) == 64
    assert "single_nodes" not in lutfile.read_header(baked["smooth"])["meta"]  # smooth: no quadrature
    assert lut.load_lut(baked["matte"]).matches(PAINTS["matte"])


def test_same_paint_is_a_cache_hit_that_computes_nothing(baked, monkeypatch):
    def fail(*args, **kwargs):
        raise AssertionError("computed on a cache hit")

    monkeypatch.setattr(table, "tabulate", fail)
    named = lut.Paint(**{**PAINTS["satin"].__dict__, "name": "my satin"})
    assert lut.bake(named, baked["satin"].parent) == baked["satin"]
    assert len({p.name for p in baked.values()}) == 3  # different types, different files


def _count_calls(monkeypatch):
    calls = []
    for name in ("facet_reflection", "smooth_single", "smooth_diffuse", "rough_single", "rough_diffuse"):
        original = getattr(models, name)

        def wrapper(*args, _original=original, _name=name, **kwargs):
            calls.append((_name, kwargs.get("mueller", True)))
            return _original(*args, **kwargs)

        monkeypatch.setattr(models, name, wrapper)
    return calls


def test_a_type_bakes_every_component_once(tmp_path, monkeypatch):
    """Every component of the type is baked whatever the colours (so any
    colour renders from it), each model evaluated once per chunk, M00 only;
    smooth types never run the rough models."""
    calls = _count_calls(monkeypatch)
    lut.bake(lut.Paint(n=1.5, rho=0.5, single=0.0), tmp_path, resolution=(8, 6, 4))
    assert {c[0] for c in calls} == {"smooth_diffuse", "smooth_single"}
    calls.clear()
    lut.bake(lut.Paint(n=1.5, rho=0.0, single=0.3, slope=0.2, facet=0.0), tmp_path, resolution=(8, 6, 4))
    assert {c[0] for c in calls} == {"facet_reflection", "rough_single", "rough_diffuse"}
    assert all(mueller is False for _, mueller in calls)  # M00 only


def test_progress_is_reported(tmp_path):
    seen = []
    lut.bake(
        lut.Paint(rho=0.3), tmp_path, resolution=(40, 30, 20), progress=lambda done, total: seen.append((done, total))
    )
    assert seen[-1][0] == seen[-1][1] == 40 * 30 * 20 and len(seen) > 1


def _refuses_truncated_and_junk(good, tmp_path):
    """A LUT cut in half and a file that is no image are refused by name."""
    data = good.read_bytes()
    truncated = tmp_path / "truncated.exr"
    truncated.write_bytes(data[: len(data) // 2])
    with pytest.raises(lut.LUTError, match="truncated"):
        lut.load_lut(truncated)
    (tmp_path / "junk.exr").write_bytes(b"not an image at all")
    with pytest.raises(lut.LUTError, match="not a readable EXR"):
        lut.load_lut(tmp_path / "junk.exr")


def test_missing_truncated_altered_and_foreign_files_are_refused(baked, tmp_path):
    with pytest.raises(lut.LUTError, match="no such LUT file"):
        lut.load_lut(tmp_path / "nothing.exr")
    _refuses_truncated_and_junk(baked["smooth"], tmp_path)
    # Altered pixels under the original header.
    table_, header = lutfile.read(baked["smooth"])
    altered = tmp_path / "altered.exr"
    lutfile.write(altered, table_, header["meta"])
    oiio = lutfile._oiio()
    buf = oiio.ImageBuf(str(altered))
    pixels = buf.get_pixels(oiio.FLOAT)
    pixels[3, 3, 0] += 0.01
    buf.set_pixels(oiio.ROI(), pixels)
    buf.write(str(altered))
    with pytest.raises(lut.LUTError, match="does not match its hash"):
        lut.load_lut(altered)


def test_other_format_version_is_refused(baked, tmp_path, monkeypatch):
    table_, header = lutfile.read(baked["smooth"])
    monkeypatch.setattr(lutfile, "FORMAT_VERSION", 99)
    future = lutfile.write(tmp_path / "future.exr", table_, header["meta"])
    monkeypatch.undo()
    with pytest.raises(lut.LUTError, match="format version 99; this version of Paint LUT reads 2"):
        lut.load_lut(future)


def test_damaged_cache_entry_is_baked_again(tmp_path):
    paint = lut.Paint(rho=0.4, slope=0.1)
    path = lut.bake(paint, tmp_path, resolution=(8, 6, 4))
    good = path.read_bytes()
    path.write_bytes(good[:100])
    assert lut.bake(paint, tmp_path, resolution=(8, 6, 4)) == path
    assert lut.load_lut(path).meta["resolution"] == [8, 6, 4]


def test_interrupted_write_leaves_no_partial_file_and_keeps_the_old_one(tmp_path, monkeypatch):
    paint = lut.Paint(rho=0.4)
    path = lut.bake(paint, tmp_path, resolution=(8, 6, 4))
    before = path.read_bytes()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(table, "tabulate", interrupted)
    with pytest.raises(KeyboardInterrupt):
        lut.bake(paint, tmp_path, resolution=(8, 6, 4), force=True)
    monkeypatch.undo()
    oiio = lutfile._oiio()
    original = oiio.ImageOutput.write_image

    def failing_write(self, *args, **kwargs):
        original(self, *args, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(oiio.ImageOutput, "write_image", failing_write)
    with pytest.raises(KeyboardInterrupt):
        lut.bake(paint, tmp_path, resolution=(8, 6, 4), force=True)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"resolution": (64, 1, 16)}, "resolution must be three whole numbers"),
        ({"resolution": (64, 32)}, "resolution must be three whole numbers"),
        ({"resolution": (64.5, 32, 16)}, "resolution must be three whole numbers"),
        ({"single_nodes": (0, 4)}, r"single_nodes\[0\] must be a whole number >= 1"),
    ],
)
def test_bad_bake_options(tmp_path, kw, message):
    with pytest.raises(ValueError, match=message):
        lut.bake(lut.Paint(rho=0.3, single=0.2, slope=0.2), tmp_path, **kw)
    with pytest.raises(ValueError, match="paint must be a lut.Paint"):
        lut.bake({"rho": 0.3}, tmp_path)


def test_meta_is_plain_json(baked):
    meta = lutfile.read_header(baked["matte"])["meta"]
    assert json.loads(json.dumps(meta)) == meta


def test_files_without_openimageio(tmp_path, monkeypatch):
    """Blender 4.2-4.3 have no OpenImageIO module: lut.lutfiles.exr writes and reads
    the same files, and each backend reads the other's."""
    paint = lut.Paint(rho=(0.7, 0.5, 0.2), single=0.2, slope=0.1)
    with_oiio = lut.bake(paint, tmp_path / "oiio", resolution=(8, 6, 4))
    monkeypatch.setattr(lutfile, "_oiio", lambda: None)
    without = lut.bake(paint, tmp_path / "numpy", resolution=(8, 6, 4))
    assert with_oiio.name == without.name
    a, b = lut.load_lut(with_oiio), lut.load_lut(without)  # numpy reads OpenImageIO's ZIP file
    np.testing.assert_array_equal(a.data, b.data)
    _refuses_truncated_and_junk(without, tmp_path)
    monkeypatch.undo()
    np.testing.assert_array_equal(lut.load_lut(without).data, a.data)  # OpenImageIO reads ours


def test_a_lut_keyed_by_its_whole_meta_still_reads(tmp_path, monkeypatch):
    """Files written when r̄ was part of the key (the previous release) stay
    readable; a key that is neither is refused."""
    import hashlib

    table, header = lutfile.read(lut.bake(PAINTS["smooth"], tmp_path))
    meta = header["meta"]
    legacy = hashlib.sha256(lutfile.canonical_json(meta).encode()).hexdigest()
    assert legacy != lutfile.cache_key(meta)
    real_key = lutfile.cache_key
    for key, readable in ((legacy, True), ("0" * 64, False)):
        monkeypatch.setattr(lutfile, "cache_key", lambda m, key=key: key)
        path = lutfile.write(tmp_path / "written.exr", table, meta)
        monkeypatch.setattr(lutfile, "cache_key", real_key)
        if readable:
            assert lutfile.read(path)[1]["key"] == legacy
        else:
            with pytest.raises(lut.LUTError, match="header key does not match its meta"):
                lutfile.read(path)


def test_processes_racing_to_bake_one_type_into_one_store_leave_one_valid_set(tmp_path):
    """Four processes bake one paint type into one folder at once (a farm's
    shared store): each write is a complete file renamed into place, so
    one LUT and one weights file per engine stand, valid, and no partial
    file is left."""
    from lut.render import fitting

    root = str(pathlib.Path(__file__).resolve().parents[1])
    store = tmp_path / "store"
    code = (
        f"import sys; sys.path.insert(0, {root!r}); import lut; from lut.render import bake; "
        f"bake.bake_for_render(lut.Paint(rho=(0.2, 0.3, 0.4), slope=0.3), {str(store)!r})"
    )
    racers = [subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE) for _ in range(4)]
    for racer in racers:
        _, err = racer.communicate(timeout=300)
        assert racer.returncode == 0, err.decode()
    luts = list(store.glob("paintlut-*.exr"))
    fits = sorted(store.glob("paintfit-*.exr"))
    assert len(luts) == 1 and len(fits) == 2
    table = lut.load_lut(luts[0])  # verified against its hash
    assert all(fitting.read_fit(f).lut_key == table.key for f in fits)
    assert not [p for p in store.iterdir() if p.name.startswith(".")]


def test_a_rough_dispersive_paint_evaluates_from_its_lut(tmp_path):
    """A dispersive paint's amplitudes are recomputed from the LUT's own
    quadrature (read back from JSON as a list): the rough case evaluates,
    near the model."""
    paint = lut.Paint(n=(1.49, 0.006), rho="ColorChecker N Ohta/red", single=0.1, slope=0.3)
    table_ = lut.load_lut(lut.bake(paint, tmp_path))
    ti, ts, ps = np.radians([10.0, 40.0, 60.0]), np.radians([30.0, 50.0, 20.0]), np.array([0.5, 2.0, 3.0])
    np.testing.assert_allclose(table_.evaluate(ti, ts, ps, paint), paint.brdf(ti, ts, ps), rtol=0.02)
