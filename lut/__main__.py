"""Command line: ``python -m lut example`` prints the paper's Fig. 2
quantities for the glossy white paint from the models."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from . import __version__, examples


def _example(args) -> int:
    data = examples.fig2_glossy_white()
    print("Glossy white paint (paper Fig. 2 left): diffuse substrate under a smooth interface,")
    paint = examples.GLOSSY_WHITE
    print(f"n = {paint['n']}, rho = {paint['rho']}, theta_i = 60 deg, 45 deg linear light,")
    print("in the plane of incidence (negative theta_s: the source's side).\n")
    print(f"{'theta_s':>8} {'f_r [1/sr]':>11} {'eta [deg]':>10} {'P_c':>7} {'P':>7}")
    for row in zip(data["theta_s_deg"], data["fr"], data["eta"], data["pc"], data["p"], strict=True):
        ts, fr, eta, pc, p = row
        eta_text = "-" if np.isnan(eta) else f"{np.degrees(eta):.1f}"
        print(f"{ts:8.0f} {fr:11.5f} {eta_text:>10} {pc:7.3f} {p:7.3f}")
    print("\nAs in the paper: eta = +-90 deg (p-polarized), P_c = 0, and P rising at large angles")
    print("(eta is undefined, '-', where the light is unpolarized).")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m lut",
        description="Paint LUT: physically based paint appearance from Germer's polarized scattering models.",
    )
    parser.add_argument("--version", action="version", version=f"paint-lut {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("example", help="print the paper's Fig. 2 model curve for the glossy white paint")
    args = parser.parse_args(argv)
    return {"example": _example}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
