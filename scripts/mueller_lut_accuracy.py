"""Accuracy, bake time and size of the Mueller LUT (``lut.polarized.mueller_lut``)
on the randomised set (``lut.bench.random_paints``, fixed seed).

    .venv/bin/python scripts/mueller_lut_accuracy.py [--count N] [--directory DIR]

Prints per paint, from ``mueller_lut.accuracy``: M00's and the worst other
element's cos θi-weighted RMS error relative to M00 (θi, θs <= 80°, all
azimuths), the largest error of Mij/M00 there, the worst pointwise error at
the poles (M00, and any other element relative to M00); all five for the
table's own facet term and for the facet term in closed form (the lookup's
default for a type with one n, and the Mitsuba plugin's); the bake time (a
cache hit is baked again) and the file's size; then the worst and the
median of each column."""

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
        columns = ("M00 rms", "other", "Mij/M00", "pole M00", "pole oth") * 2
        print(f"{'':28s} {'the table':^44s}  {'facet in closed form (the default)':^44s}")
        print(f"{'paint':28s} " + " ".join(f"{c:>8s}" for c in columns) + f" {'bake s':>7s} {'MB':>5s}")
        for label, paint in bench.random_paints(args.count):
            start = time.perf_counter()
            path = mueller_lut.bake_mueller(paint, directory, force=True)
            seconds = time.perf_counter() - start
            table = mueller_lut.load_mueller_lut(path)
            row = []
            for closed in (False, True):
                found = mueller_lut.accuracy(table, paint, closed_facet=closed)
                rms = found["rms"].copy()
                m00 = rms[0, 0]
                rms[0, 0] = 0.0
                row += [100 * m00, 100 * rms.max(), found["normalised"], 100 * found["poles_m00"], 100 * found["poles"]]
            rows.append(row + [seconds, path.stat().st_size / 1e6])
            print(f"{label:28s} " + _cells(rows[-1]))
        rows = np.array(rows)
        for name, value in (("worst", rows.max(axis=0)), ("median", np.median(rows, axis=0))):
            print(f"{name:28s} " + _cells(value))


def _cells(row) -> str:
    """A row of the table: per cent, the Mij/M00 errors as they are, seconds, MB."""
    cells = [f"{v:7.2f}%" if k % 5 != 2 else f"{v:8.4f}" for k, v in enumerate(row[:10])]
    return " ".join(cells) + f" {row[10]:7.1f} {row[11]:5.1f}"


if __name__ == "__main__":
    main()
