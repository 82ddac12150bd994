"""Bake benchmark: run time against error of each preset's LUT.

    .venv/bin/python scripts/benchmark.py [--plot FILE] [--quick]

The plot goes to out/bake_benchmark.png unless --plot says otherwise; the
README's figure is made with --plot docs/figures/bake_benchmark.png.

For each preset, bakes at several resolutions and quadrature sizes (forced,
so nothing comes from the cache), measures the LUT's cos-weighted relative RMS
error against the model with converged quadrature on 2,000 random
directions (θi, θs <= 80°), prints the table and saves a plot of error
against time."""

from __future__ import annotations

import argparse
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from lut import bench  # noqa: E402
from lut.lutfiles import files, table  # noqa: E402
from lut.lutfiles.baking import BAKE_SINGLE_NODES  # noqa: E402
from lut.paint import presets  # noqa: E402

DEFAULT_PLOT = "out/bake_benchmark.png"


def parse(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plot", default=DEFAULT_PLOT, help="plot file (default: %(default)s)")
    parser.add_argument("--quick", action="store_true", help="two settings and 500 directions")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse(argv)
    paints = {name: presets.preset(name) for name in presets.PRESETS}
    settings = bench.BAKE_SETTINGS[1:3] if args.quick else bench.BAKE_SETTINGS
    report = bench.bake_time_vs_error(paints, settings, count=500 if args.quick else 2000)
    default = (tuple(table.DEFAULT_RESOLUTION), tuple(BAKE_SINGLE_NODES))
    print(f"{'preset':13} {'resolution':>14} {'single nodes':>13} {'seconds':>8} {'error':>8}")
    for name, rows in report.items():
        for r in rows:
            mark = "  <- default" if (tuple(r["resolution"]), tuple(r["single_nodes"])) == default else ""
            res, nodes = "x".join(map(str, r["resolution"])), "x".join(map(str, r["single_nodes"]))
            print(f"{name:13} {res:>14} {nodes:>13} {r['seconds']:8.2f} {100 * r['error']:7.2f}%{mark}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for name, rows in report.items():
        ax.loglog([r["seconds"] for r in rows], [100 * r["error"] for r in rows], marker="o", label=name)
    ax.axhline(1.0, color="0.6", ls=":", lw=1)
    ax.axvline(5.0, color="0.6", ls=":", lw=1)
    ax.set(xlabel="bake time [s] (2 cores)", ylabel="cos-weighted RMS error [%]", title="Bake: time against error")
    ax.legend()
    fig.tight_layout()
    out = pathlib.Path(args.plot)
    with files.atomic_target(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    print(f"\nplot: {out}")


if __name__ == "__main__":
    main()
