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
from lut import lutfile
from lut.__main__ import main

ROOT = pathlib.Path(__file__).resolve().parents[1]
SMALL = ["--resolution", "8", "6", "4"]


# ----------------------------------------------------------------------------- atomic writes


@pytest.mark.parametrize("mode", [0o600, 0o664, 0o640])
def test_atomic_writes_keep_the_mode_of_the_file_they_replace(tmp_path, mode):
    path = tmp_path / "report.json"
    path.write_text("old")
    path.chmod(mode)
    lutfile.atomic_write_bytes(path, b"new")
    assert path.read_bytes() == b"new"
    assert stat.S_IMODE(path.stat().st_mode) == mode


def test_a_new_file_gets_the_umask_mode(tmp_path):
    old = os.umask(0o027)
    try:
        lutfile.atomic_write_bytes(tmp_path / "new.json", b"x")
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
                from lut import lutfile
                with lutfile.atomic_target({str(target)!r}) as tmp:
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
        lut.bake(lut.Paint(rho=0.6), tmp_path, resolution=(8, 6, 4))  # another paint: the writer still runs
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
    with lutfile.atomic_target(tmp_path / "a.exr") as tmp:
        pathlib.Path(tmp).write_bytes(b"in progress")
        assert lutfile.remove_stale_partials(tmp_path) == []
        assert pathlib.Path(tmp).exists()
    old = tmp_path / ".b.qwertyui.partial.exr"  # an older version's name: by age
    old.write_bytes(b"")
    assert lutfile.remove_stale_partials(tmp_path) == []
    os.utime(old, (1, 1))
    assert lutfile.remove_stale_partials(tmp_path) == [old]
    assert keep.exists() and (tmp_path / "a.exr").exists()


def test_writing_onto_a_directory_fails_before_any_work(tmp_path):
    with pytest.raises(IsADirectoryError):
        lutfile.atomic_write_bytes(tmp_path, b"x")
    assert not list(tmp_path.iterdir())


def test_weights_files_carry_a_verified_hash(tmp_path):
    pixels = np.arange(18, dtype=np.float32).reshape(2, 3, 3)
    path = lutfile.write_exr(tmp_path / "w.exr", pixels, {"paintlut:closures": "('lambert',)"})
    assert np.array_equal(lutfile.read_exr(path), pixels)
