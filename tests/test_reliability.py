"""Reliability of the library and the command line: atomic writes keep
permissions and clean up after killed writers, bad input gets one line
naming the parameter, and no option is silently ignored."""

import json
import os
import pathlib
import signal
import stat
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lut
from lut.__main__ import main
from lut.lutfiles import files
from lut.lutfiles import format as lutfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
SMALL = ["--resolution", "8", "6", "4"]


# ----------------------------------------------------------------------------- atomic writes


@pytest.mark.parametrize("mode", [0o600, 0o664, 0o640])
def test_atomic_writes_keep_the_mode_of_the_file_they_replace(tmp_path, mode):
    path = tmp_path / "report.json"
    path.write_text("old")
    path.chmod(mode)
    files.atomic_write_bytes(path, b"new")
    assert path.read_bytes() == b"new"
    assert stat.S_IMODE(path.stat().st_mode) == mode


def test_a_new_file_gets_the_umask_mode(tmp_path):
    old = os.umask(0o027)
    try:
        files.atomic_write_bytes(tmp_path / "new.json", b"x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new.json").stat().st_mode) == 0o640


def test_the_partial_file_of_a_killed_writer_is_removed_by_the_next_bake(tmp_path):
    paint = lut.Paint(rho=0.3)
    target = lut.lut_path(paint, tmp_path, resolution=(8, 6, 4))
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            textwrap.dedent(
                f"""
                import sys, time
                from lut.lutfiles import files
                with files.atomic_target({str(target)!r}) as tmp:
                    open(tmp, "wb").write(b"half a LUT")
                    print("writing", flush=True)
                    time.sleep(600)
                """
            ),
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    try:
        assert child.stdout.readline().strip() == "writing"
        partials = list(tmp_path.glob(".*.partial*"))
        assert len(partials) == 1
        lut.bake(lut.Paint(n=1.6, rho=0.6), tmp_path, resolution=(8, 6, 4))  # another type: the writer still runs
        assert partials[0].exists()
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
        child.stdout.close()
    assert partials[0].exists()  # kill -9: nothing cleaned up
    assert lut.bake(paint, tmp_path, resolution=(8, 6, 4)) == target
    assert not list(tmp_path.glob(".*.partial*"))
    lut.load_lut(target)


def test_remove_stale_partials_spares_live_writers_and_other_files(tmp_path):
    keep = tmp_path / "notes.partial.txt"  # not hidden: not ours
    keep.write_text("x")
    with files.atomic_target(tmp_path / "a.exr") as tmp:
        pathlib.Path(tmp).write_bytes(b"in progress")
        assert files.remove_stale_partials(tmp_path) == []
        assert pathlib.Path(tmp).exists()
    old = tmp_path / ".b.qwertyui.partial.exr"  # an older version's name: by age
    old.write_bytes(b"")
    assert files.remove_stale_partials(tmp_path) == []
    os.utime(old, (1, 1))
    assert files.remove_stale_partials(tmp_path) == [old]
    assert keep.exists() and (tmp_path / "a.exr").exists()


def test_writing_onto_a_directory_fails_before_any_work(tmp_path):
    with pytest.raises(IsADirectoryError):
        files.atomic_write_bytes(tmp_path, b"x")
    assert not list(tmp_path.iterdir())


def test_weights_files_carry_a_verified_hash(tmp_path):
    pixels = np.arange(18, dtype=np.float32).reshape(2, 3, 3)
    path = lutfile.write_exr(tmp_path / "w.exr", pixels, {"paintlut:closures": "('lambert',)"})
    assert np.array_equal(lutfile.read_exr(path), pixels)


def test_a_table_that_is_not_finite_is_never_written(tmp_path):
    import warnings

    paint = lut.Paint(rho=0.5, slope=1e-20)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # float32 overflow while tabulating
        with pytest.raises(ValueError, match="not finite"):
            lut.bake(paint, tmp_path, resolution=(8, 6, 4))
    assert not list(tmp_path.iterdir())


# ----------------------------------------------------------------------------- command line: errors


def _error_line(capsys):
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--resolution", "4096", "4096", "4096"], "product N_u*N_theta_d*N_phi_d of at most 4194304"),
        (["--resolution", "1024", "1024", "8"], "got 1024 1024 8 (8388608 nodes)"),
        (["--resolution", "4096", "1024", "1"], "N_phi_d must be a whole number in [2, 4096], got 1"),
        (["--single-nodes", "1000", "1000"], "--single-nodes must be two whole numbers in [1, 64]"),
        (["--n", "1e6"], "n must be in [1, 4], got 1000000.0"),
        (["--slope", "1e300"], "slope must be 0 (smooth) or in [0.001, 3], got 1e+300"),
        (["--slope", "1e-20"], "slope must be 0 (smooth) or in [0.001, 3], got 1e-20"),
    ],
)
def test_out_of_range_options_get_one_line_naming_the_range(argv, message, tmp_path, capsys):
    assert main(["bake", *argv, "--out", str(tmp_path)]) == 2
    assert message in _error_line(capsys)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ({"rho": {"spectrum": "ColorChecker N Ohta/red", "scale": None}}, "rho: spectrum scale must be a finite"),
        ({"rho": {"spectrum": "ColorChecker N Ohta/red", "scale": float("nan")}}, "got nan"),
        ({"space": ["ACEScg"]}, "space must be one of 'Linear Rec.709', 'Linear Rec.2020', 'ACEScg', got ['ACEScg']"),
        ({"rho": {"wavelengths": [0.38, 0.55, 0.78], "values": [0.1, 0.5, 0.9]}}, "micrometres? give nanometres"),
        ({"rho": {"wavelengths": [400, 700], "values": [0.5, "x"]}}, "rho: spectrum wavelengths and values must be"),
        ({"single": {"values": [0.5]}}, "single: a spectrum needs 'wavelengths' and 'values'"),
        ({"g": "strong"}, "g must be a real number with -1 < g < 1, got 'strong'"),
        ({"name": 3}, "name must be text, got 3"),
        ({"rho": None}, "rho must be an RGB triple"),
    ],
)
def test_bad_paint_files_name_the_file_and_the_parameter(content, message, tmp_path, capsys):
    path = tmp_path / "paint.json"
    path.write_text(json.dumps(content))
    assert main(["bake", "--paint", str(path), "--out", str(tmp_path), *SMALL]) == 2
    line = _error_line(capsys)
    assert f"paint file {str(path)!r}" in line and message in line


def test_a_spectrum_in_micrometres_is_refused_not_flat_grey():
    with pytest.raises(ValueError, match="must be in nm"):
        lut.Spectrum([0.38, 0.5, 0.78], [0.1, 0.5, 0.9])
    with pytest.raises(ValueError, match="scale must be a finite real number >= 0, got nan"):
        lut.Spectrum([400, 700], [0.1, 0.9], scale=float("nan"))


def test_files_that_are_not_utf8_are_named(tmp_path, capsys):
    toml = tmp_path / "paint.toml"
    toml.write_bytes(b'rho = 0.5\nname = "caf\xe9"\n')
    assert main(["bake", "--paint", str(toml), "--out", str(tmp_path)]) == 2
    assert f"paint file {str(toml)!r} is not UTF-8 text" in _error_line(capsys)
    csv = tmp_path / "spectrum.csv"
    csv.write_bytes(b"# r\xe9flectance\n400,0.1\n700,0.9\n")
    toml.write_text(f"rho = {json.dumps(str(csv))}\n")
    assert main(["bake", "--paint", str(toml), "--out", str(tmp_path)]) == 2
    assert f"spectrum file {str(csv)!r} is not UTF-8 text" in _error_line(capsys)


# ----------------------------------------------------------------------------- command line: no silent surprises


def _baked_paint(capsys):
    """The type the printed LUT holds, and the colour inputs printed with it."""
    out = capsys.readouterr().out
    return {**lut.load_lut(out.split()[0]).meta["type"], "out": out}


def test_options_override_a_preset_and_a_paint_file(tmp_path, capsys):
    assert main(["bake", "--preset", "green_carc", "--n", "2", "--out", str(tmp_path), *SMALL]) == 0
    paint = _baked_paint(capsys)
    assert paint["n"] == 2.0 and paint["slope"] == lut.preset("green_carc").slope
    toml = tmp_path / "paint.toml"
    toml.write_text("rho = 0.4\nslope = 0.1\n")
    assert main(["bake", "--paint", str(toml), "--slope", "0.3", "--out", str(tmp_path), *SMALL]) == 0
    paint = _baked_paint(capsys)
    assert paint["slope"] == 0.3 and "Pigment Color: (0.4, 0.4, 0.4)" in paint["out"]
    # An override the preset cannot take is refused, not ignored.
    assert main(["bake", "--preset", "glossy_red", "--rho", "0.1", "0.2", "0.3", "--out", str(tmp_path)]) == 2
    assert "rho must be a Spectrum or a grey value in a spectral paint" in _error_line(capsys)


def test_info_takes_several_files(tmp_path, capsys):
    assert main(["example", "--out", str(tmp_path), *SMALL]) == 0
    luts = sorted((tmp_path / "luts").glob("paintlut-*.exr"))
    capsys.readouterr()
    assert len(luts) == 3
    assert main(["info", *map(str, luts)]) == 0
    out = capsys.readouterr().out
    assert [line.split(":")[0] for line in out.splitlines() if line.startswith(str(tmp_path))] == list(map(str, luts))
    assert main(["info", str(luts[0]), str(tmp_path / "missing.exr")]) == 2
    captured = capsys.readouterr()
    assert str(luts[0]) in captured.out and "missing.exr: no such LUT file" in captured.err


def test_info_checks_a_lut_files_name_against_its_key(tmp_path, capsys):
    """A LUT copied under another type's name is whole (its hash verifies)
    but not what its name says: info says so and fails; a file under any
    other name is not judged by its name."""
    one = lut.bake(lut.Paint(rho=0.5), tmp_path, resolution=(8, 6, 4))
    other = lut.bake(lut.Paint(n=1.7, rho=0.5), tmp_path, resolution=(8, 6, 4))
    other.write_bytes(one.read_bytes())
    assert main(["info", str(one)]) == 0
    capsys.readouterr()
    assert main(["info", str(other)]) == 2
    err = capsys.readouterr().err
    assert f"its name says key {other.name[9:33]}" in err and "another paint type" in err
    renamed = tmp_path / "mine.exr"
    renamed.write_bytes(one.read_bytes())
    assert main(["info", str(renamed)]) == 0


def test_info_into_a_closed_pipe_is_quiet(tmp_path):
    path = lut.bake(lut.Paint(rho=0.5), tmp_path, resolution=(8, 6, 4))
    read_end, write_end = os.pipe()
    os.close(read_end)  # as `head` does after its lines: every write fails with EPIPE
    try:
        done = subprocess.run(
            [sys.executable, "-m", "lut", "info", str(path), str(path)],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
    finally:
        os.close(write_end)
    assert done.stderr == "" and done.returncode == 141


def test_ctrl_c_ends_with_one_line_and_status_130(tmp_path, capsys, monkeypatch):
    from lut.lutfiles import baking

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(baking, "bake", interrupted)
    assert main(["bake", "--rho", "0.5", "--out", str(tmp_path)]) == 130
    assert _error_line(capsys) == "interrupted"


# ----------------------------------------------------------------------------- clean-up


def test_clean_removes_only_luts_and_weights_nothing_keeps(tmp_path, capsys):
    from lut.lutfiles import cleanup

    kept = lut.bake(lut.Paint(rho=0.2), tmp_path, resolution=(8, 6, 4))
    gone = lut.bake(lut.Paint(n=1.6, rho=0.7), tmp_path, resolution=(8, 6, 4))  # another paint type
    for path in (kept, gone):
        for prefix in ("paintfit-cycles-", "paintfit-eevee50-f6-", "paintfit-eevee50c-f8-"):
            path.with_name(path.name.replace("paintlut-", prefix)).write_bytes(b"weights")
    other = tmp_path / "notes.exr"
    other.write_bytes(b"x")
    stale = tmp_path / f".{gone.stem}.qwertyui.partial.exr"
    stale.write_bytes(b"")
    os.utime(stale, (1, 1))
    before = sorted(tmp_path.iterdir())

    assert main(["clean", str(tmp_path), "--keep", str(kept), "--dry-run"]) == 0
    assert sorted(tmp_path.iterdir()) == before
    assert "would remove 5 file(s)" in capsys.readouterr().out
    assert main(["clean", str(tmp_path), "--keep", str(kept)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [kept.name, "notes.exr", kept.name.replace("paintlut-", "paintfit-cycles-"),
         kept.name.replace("paintlut-", "paintfit-eevee50-f6-"),
         kept.name.replace("paintlut-", "paintfit-eevee50c-f8-")]
    )  # fmt: skip
    assert "removed 5 file(s)" in capsys.readouterr().out
    with pytest.raises(ValueError, match="not a LUT"):
        cleanup.clean(tmp_path, keep=[other])
    assert main(["clean", str(tmp_path / "missing"), "--keep"]) == 2
    assert "no such directory" in _error_line(capsys)


# ----------------------------------------------------------------------------- the README's promises


def test_the_readme_headless_snippet_gives_the_status_its_comment_promises(tmp_path):
    pytest.importorskip("bpy")
    import re

    readme = (ROOT / "README.md").read_text()
    snippet = next(block for block in re.findall(r"```python\n(.*?)```", readme, re.S) if "api.bake_scene" in block)
    promised = re.search(r'api\.bake_scene\(.*\)\s*#\s*\{"red paint": BakeStatus\(state="(\w+)"', snippet)
    assert promised, snippet
    done = subprocess.run(
        [sys.executable, "-c", snippet + "\nprint({name: s.state for name, s in status.items()})\n"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(tmp_path)},  # an unsaved file bakes into TMPDIR
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == repr({"red paint": promised[1]})


def test_the_readme_info_command_takes_the_example_luts(tmp_path, capsys, monkeypatch):
    readme = (ROOT / "README.md").read_text()
    assert "python -m lut info out/luts/paintlut-*.exr" in readme
    monkeypatch.chdir(tmp_path)
    assert main(["example", *SMALL]) == 0
    capsys.readouterr()
    files = sorted(str(p) for p in pathlib.Path("out/luts").glob("paintlut-*.exr"))  # as the shell expands it
    assert len(files) == 3 and main(["info", *files]) == 0
    assert capsys.readouterr().out.count("(verified)") == 3


def test_the_bake_benchmark_writes_no_tracked_file_by_default():
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import benchmark
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    plot = benchmark.parse([]).plot
    tracked = subprocess.run(["git", "ls-files", "--error-unmatch", plot], cwd=ROOT, capture_output=True)
    assert tracked.returncode != 0, f"{plot} is a tracked file"
    assert not pathlib.Path(plot).parts[0] == "docs"


def test_a_damaged_cached_lut_baked_again_is_reported_computed(tmp_path):
    """A cached LUT that fails its hash is baked again, and the report says
    so (not "found cached"); an intact one is reported cached."""
    from lut.render import bake as render_bake

    paint = lut.Paint(n=1.5, rho=(0.3, 0.3, 0.3))
    options = {"targets": ("CYCLES",), "resolution": (8, 6, 4)}
    assert render_bake.bake_for_render(paint, tmp_path, **options).computed == ["lut", "CYCLES"]
    assert render_bake.bake_for_render(paint, tmp_path, **options).computed == []
    path = lut.lutfiles.baking.lut_path(paint, tmp_path, resolution=(8, 6, 4))
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    assert render_bake.bake_for_render(paint, tmp_path, **options).computed[0] == "lut"
    lut.load_lut(path)  # whole again


def test_an_index_given_as_a_numpy_scalar_is_a_number():
    assert lut.Paint(n=np.float32(1.5), rho=0.5).n == pytest.approx(1.5)
    with pytest.raises(ValueError, match=r"n must be a finite real number > 0, got -1.0"):
        lut.Paint(n=np.float64(-1.0), rho=0.5)


def test_out_that_is_a_file_is_refused_before_any_work(tmp_path, capsys):
    target = tmp_path / "a_file"
    target.write_text("kept")
    assert main(["bake", *SMALL, "--out", str(target)]) == 2
    assert _error_line(capsys) == f"error: --out must be a folder, got a file: {target}"
    assert target.read_text() == "kept"


def test_a_colour_of_two_values_gets_the_bake_commands_usage(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["bake", "--rho", "0.1", "0.2", "--out", str(tmp_path)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "usage: python -m lut bake" in err and "--rho takes one grey value, three RGB values" in err


def test_a_damaged_file_gives_one_line_not_the_libraries_raw_errors(tmp_path):
    """OpenEXR's core prints a raw line per damaged chunk: a truncated LUT
    gives the one error naming it, and nothing else, on stderr."""
    pytest.importorskip("OpenImageIO")
    path = lut.bake(lut.Paint(rho=0.5), tmp_path, resolution=(32, 16, 8))
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 3])
    done = subprocess.run([sys.executable, "-m", "lut", "info", str(path)], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and done.stderr.startswith(f"error: {path}"), done.stderr
    assert "EXR_ERR" not in done.stderr


def test_a_folder_that_refuses_writes_is_named_not_the_hidden_file(tmp_path, monkeypatch):
    """When the folder refuses the temporary file (read-only, full), the
    error names the file asked for and its folder."""
    import tempfile

    def refuse(**kwargs):
        raise PermissionError(13, "Permission denied", str(tmp_path / ".a.123@host.x.partial.exr"))

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(PermissionError, match=r"cannot write a\.exr into .*: Permission denied") as error:
        files.atomic_write_bytes(tmp_path / "a.exr", b"x")
    assert ".partial" not in str(error.value)


def test_files_read_where_python_has_no_stderr(tmp_path, monkeypatch):
    """An embedded interpreter (or pythonw) may have no sys.stderr: reading
    a LUT still works, and a damaged one still raises its LUTError."""
    path = lut.bake(lut.Paint(rho=0.5), tmp_path, resolution=(8, 6, 4))
    monkeypatch.setattr(sys, "stderr", None)
    assert lut.load_lut(path).key
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    with pytest.raises(lut.LUTError):
        lut.load_lut(path)
