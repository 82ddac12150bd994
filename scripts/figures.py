"""Reproduce the paper's Figs. 1-3 from the models as PNG plots.

    .venv/bin/python scripts/figures.py [--out DIR]

Writes fig1.png, fig2_white.png, fig2_red.png and fig3_carc.png into DIR
(default: figures/ in the current folder, so a trial run never replaces the
documented ones; ``--out docs/figures`` makes those).  See lut/figures.py."""

from __future__ import annotations

import argparse
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from lut import figures  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="figures", help="output directory (default: %(default)s)")
    args = parser.parse_args(argv)
    for path in figures.all_figures(args.out):
        print(path)


if __name__ == "__main__":
    main()
