"""Benchmark the model core: throughput against NIST SCATMECH, M00-only
against full Mueller, and the rough models' run time against error (with the
paper's random-pairs method for comparison).

    .venv/bin/python scripts/benchmark_models.py [--quick]

SCATMECH's per-call cost is timed in the same run, on the same machine
(scripts/scatmech_speed.py, run by this interpreter or by the one given with
--scatmech-python, which has pySCATMECH); where there is none, the table has
no ratio: a cost stored from another machine is not compared with local
timings."""

from __future__ import annotations

import argparse
import json
import pathlib
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from lut import bench  # noqa: E402

SPEED = pathlib.Path(__file__).parent / "scatmech_speed.py"


def scatmech_cost(python):
    """pySCATMECH's microseconds per evaluation, timed now by ``python``
    (None: this interpreter), or None where that Python has no pySCATMECH."""
    done = subprocess.run(
        [python or sys.executable, str(SPEED)], capture_output=True, text=True, cwd=SPEED.parent
    )  # fmt: skip
    if done.returncode != 0:
        return None
    return json.loads(done.stdout)["microseconds_per_evaluation"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="a smaller table (32x32x16) and fewer settings")
    parser.add_argument("--scatmech-python", metavar="PYTHON", help="a Python with pySCATMECH, to time it here")
    args = parser.parse_args(argv)
    scatmech = scatmech_cost(args.scatmech_python)
    if scatmech is None:
        print("pySCATMECH not found (give --scatmech-python): the table has no ratio to SCATMECH\n")

    count = 20_000 if args.quick else 100_000
    for grid in (False, True):
        what = "a grid of about" if grid else "random"
        print(f"Closed-form models on {what} {count} angles (best of 3; time per evaluation)")
        print(f"{'model':20} {'SCATMECH us':>12} {'full us':>9} {'M00 us':>8} {'vs SCATMECH':>12} {'full/M00':>9}")
        for name, row in bench.throughput(count, grid=grid).items():
            full, m00 = row["full"] * 1e6, row["m00"] * 1e6
            if scatmech is None:
                print(f"{name:20} {'-':>12} {full:9.3f} {m00:8.3f} {'-':>12} {full / m00:9.1f}")
                continue
            ratio = scatmech[name] / full
            print(f"{name:20} {scatmech[name]:12.2f} {full:9.3f} {m00:8.3f} {ratio:11.0f}x {full / m00:9.1f}")
        print()

    shape = (32, 32, 16) if args.quick else (64, 64, 32)
    print(f"\nRough models: a {shape[0]}x{shape[1]}x{shape[2]} (theta_i, theta_s, phi_s) table of M00")
    kw = {"shape": shape}
    if args.quick:
        kw.update(single_nodes=((3, 4), (4, 6)), diffuse_nodes=((8, 8), (16, 16)), mc_pairs=(100, 1000), sample=400)
    for paint, rows in bench.rough_time_vs_error(**kw).items():
        print(f"\n{paint}")
        print(f"{'model':14} {'method':24} {'seconds':>9} {'RMS error':>10}")
        for r in rows:
            print(f"{r['model']:14} {r['method']:24} {r['seconds']:9.2f} {r['rms_error']:10.2e}")
        for target in ("quadrature (3, 4)", "quadrature (4, 6)"):
            if any(r["method"] == target for r in rows):
                ratio, pairs = bench.speedup_at_equal_error(rows, target)
                print(f"  {target}: {ratio:.0f}x faster than random pairs at equal error (~{pairs:.0f} pairs needed)")


if __name__ == "__main__":
    main()
