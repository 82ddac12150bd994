"""Accuracy, bake time and size of the Mueller LUT (``lut.polarized.mueller_lut``)
on the randomised set (``lut.bench.random_paints``, fixed seed).

    .venv/bin/python scripts/mueller_lut_accuracy.py [--count N] [--directory DIR]

Prints per paint, from ``mueller_lut.accuracy``: M00's and the worst other
element's cos θi-weighted RMS error relative to M00 (θi, θs <= 80°, all
azimuths), the worst pointwise error at the poles (M00, and any other
element relative to M00), the bake time (a cache hit is baked again) and the
file's size; then the worst and the median of each column."""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from lut import bench  # noqa: E402
from lut.polarized import mueller_lut  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=24, help="paints of the randomised set (default 24)")
    parser.add_argument("--directory", type=pathlib.Path, help="where to bake (default: a temporary directory)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        directory = args.directory or pathlib.Path(tmp)
        rows = []
        print(
            f"{'paint':28s} {'M00 rms':>8s} {'other':>8s} {'pole M00':>9s} {'pole oth':>9s} {'bake s':>7s} {'MB':>5s}"
        )
        for label, paint in bench.random_paints(args.count):
            start = time.perf_counter()
            path = mueller_lut.bake_mueller(paint, directory, force=True)
            seconds = time.perf_counter() - start
            found = mueller_lut.accuracy(mueller_lut.load_mueller_lut(path), paint)
            rms = found["rms"].copy()
            m00 = rms[0, 0]
            rms[0, 0] = 0.0
            row = (100 * m00, 100 * rms.max(), 100 * found["poles_m00"], 100 * found["poles"], seconds,
                   path.stat().st_size / 1e6)  # fmt: skip
            rows.append(row)
            print(
                f"{label:28s} {row[0]:7.2f}% {row[1]:7.2f}% {row[2]:8.2f}% {row[3]:8.2f}% {row[4]:7.1f} {row[5]:5.1f}"
            )
        rows = np.array(rows)
        for name, value in (("worst", rows.max(axis=0)), ("median", np.median(rows, axis=0))):
            print(f"{name:28s} " + " ".join(f"{v:7.2f}%" for v in value[:2]) + " "
                  + " ".join(f"{v:8.2f}%" for v in value[2:4]) + f" {value[4]:7.1f} {value[5]:5.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
