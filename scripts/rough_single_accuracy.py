"""Accuracy of ``rough_single``'s quadrature against a converged one.

    .venv/bin/python scripts/rough_single_accuracy.py [--paints N] [--geometries N] [--seed S]

Random paints (n 1.3-1.8, g -0.5-0.8, slopes spread over the panel's range
0.05-3 on a log scale, plus slope 3 exactly) with both slope distributions,
and random geometries per paint (θi, θs <= 80°, φs anywhere; a fifth of them
at normal incidence and a tenth at normal exit, where the errors used to be
largest).  For each node setting prints, per distribution, the worst and the
median relative error of M00 and the worst Mueller element error relative to
M00, all against ``nodes=(16, 32)`` (which the script checks against
(24, 48) on part of the set)."""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from lut import models  # noqa: E402
from lut.lutfiles.baking import BAKE_SINGLE_NODES  # noqa: E402
from lut.models.rough import SINGLE_NODES  # noqa: E402

REFERENCE = (16, 32)
CHECK = (24, 48)


def paints(count, rng):
    slopes = np.exp(rng.uniform(np.log(0.05), np.log(3.0), count))
    slopes[0] = 3.0
    for dist in ("gaussian", "exponential"):
        for slope in slopes:
            yield {
                "n": rng.uniform(1.3, 1.8),
                "g": rng.uniform(-0.5, 0.8),
                "slope": float(slope),
                "distribution": dist,
            }


def geometries(count, rng):
    ti = rng.uniform(0.0, np.radians(80.0), count)
    ts = rng.uniform(0.0, np.radians(80.0), count)
    ps = rng.uniform(-np.pi, np.pi, count)
    ti[: count // 5] = 0.0
    ts[count // 5 : count // 5 + count // 10] = 0.0
    return ti, ts, ps


def errors(got, ref):
    m00 = ref[..., 0, 0]
    return np.abs(got[..., 0, 0] / m00 - 1.0), np.max(np.abs(got - ref), axis=(-2, -1)) / m00


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paints", type=int, default=10, help="paints per distribution (default: %(default)s)")
    parser.add_argument("--geometries", type=int, default=30, help="geometries per paint (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=2026, help="random seed (default: %(default)s)")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    settings = {"default": SINGLE_NODES, "bake": BAKE_SINGLE_NODES}
    stats = {(d, k): ([], []) for d in ("gaussian", "exponential") for k in settings}
    worst_paint = {}
    check = []
    for number, paint in enumerate(paints(args.paints, rng)):
        ti, ts, ps = geometries(args.geometries, rng)
        ref = models.rough_single(ti, ts, ps, nodes=REFERENCE, **paint)
        if number % 4 == 0:
            sub = slice(0, 10)
            check.append(np.max(errors(models.rough_single(ti[sub], ts[sub], ps[sub], nodes=CHECK, **paint), ref[sub])))
        for key, nodes in settings.items():
            e00, elem = errors(models.rough_single(ti, ts, ps, nodes=nodes, **paint), ref)
            stats[(paint["distribution"], key)][0].append(e00)
            stats[(paint["distribution"], key)][1].append(elem)
            label = (paint["distribution"], key)
            if label not in worst_paint or np.max(e00) > worst_paint[label][0]:
                worst_paint[label] = (np.max(e00), paint)
    print(f"reference {REFERENCE} against {CHECK}: worst difference {100 * max(check):.4f}% of M00")
    print(f"{'distribution':12} {'setting':8} {'nodes':>7} {'worst M00':>10} {'median M00':>11} {'worst element':>14}")
    for (dist, key), (e00, elem) in stats.items():
        e00, elem = np.concatenate(e00), np.concatenate(elem)
        nodes = "x".join(map(str, settings[key]))
        print(
            f"{dist:12} {key:8} {nodes:>7} {100 * e00.max():9.3f}% {100 * np.median(e00):10.4f}% "
            f"{100 * elem.max():13.3f}%"
        )
    for (dist, key), (worst, paint) in worst_paint.items():
        where = f"slope {paint['slope']:.3f}, n {paint['n']:.3f}, g {paint['g']:.3f}"
        print(f"worst {dist} {key}: {100 * worst:.3f}% at {where}")


if __name__ == "__main__":
    main()
