"""Command line of Paint LUT.

    python -m lut example [--out DIR]         bake the three presets, draw the paper's figures
    python -m lut bake --preset NAME [...]    bake one paint into a LUT file
    python -m lut info FILE                   describe a LUT file

Errors are reported as one line on standard error, with exit status 2."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys
import time
import tomllib

from . import __version__, baking, colour_management, examples, figures, lutfile, presets, table
from .baking import BAKE_SINGLE_NODES
from .models.rough import DIFFUSE_NODES
from .paint import Paint

DEFAULT_OUT = "out"


def _progress_bar(label):
    """A tqdm bar that appears only if the bake takes longer than a second
    (and only on a terminal)."""
    from tqdm import tqdm

    bar = tqdm(total=None, desc=label, unit="node", delay=1.0, leave=False, file=sys.stderr, disable=None)

    def update(done, total):
        if bar.total is None:
            bar.total = total
        bar.update(done - bar.n)

    return bar, update


def _bake_one(paint, out, args, label):
    bar, update = _progress_bar(label)
    start = time.perf_counter()
    try:
        path = baking.bake(
            paint,
            out,
            resolution=args.resolution,
            single_nodes=args.single_nodes,
            diffuse_nodes=args.diffuse_nodes,
            force=args.force,
            progress=update,
        )
    finally:
        bar.close()
    return path, time.perf_counter() - start


def _paint_from_args(args) -> Paint:
    if args.preset:
        return presets.preset(args.preset, args.space or colour_management.DEFAULT_SPACE)
    if args.paint:
        path = pathlib.Path(args.paint)
        try:
            text = path.read_text()
        except OSError as exc:
            raise ValueError(f"cannot read paint file {str(path)!r}: {exc.strerror}") from None
        try:
            data = tomllib.loads(text) if path.suffix.lower() == ".toml" else json.loads(text)
        except (tomllib.TOMLDecodeError, json.JSONDecodeError) as exc:
            raise ValueError(
                f"paint file {str(path)!r} is not valid {path.suffix[1:].upper() or 'JSON'}: {exc}"
            ) from None
        if args.space:
            data = {**data, "space": args.space}
        return Paint.from_dict(data)
    fields = {}
    for key in ("n", "g", "slope", "distribution", "facet", "space"):
        value = getattr(args, key)
        if value is not None:
            fields[key] = value
    for key in ("rho", "single"):
        value = getattr(args, key)
        if value is not None:
            fields[key] = value[0] if len(value) == 1 else value
    return Paint(**fields)


def _cmd_bake(args) -> int:
    paint = _paint_from_args(args)
    path, seconds = _bake_one(paint, args.out, args, paint.name or "bake")
    print(f"{path}  ({seconds:.2f} s)")
    return 0


def _cmd_info(args) -> int:
    _, header = lutfile.read(args.file)  # verifies the content hash
    meta = header["meta"]
    width, height, channels = header["size"]
    print(f"{args.file}: Paint LUT format {meta['format']}, {width}x{height} pixels, {channels} channels (Non-Color)")
    print(f"  working space   {meta['space']}")
    print(f"  resolution      {meta['resolution']} (N_u, N_theta_d, N_phi_d)")
    print(f"  parameterization {meta['parameterization']}")
    for key in ("single_nodes", "diffuse_nodes"):
        if key in meta:
            print(f"  {key:15} {meta[key]}")
    print(f"  content hash    {header['hash']} (verified)")
    print("  paint:")
    for key, value in meta["paint"].items():
        if isinstance(value, dict):
            value = f"spectrum {value.get('spectrum')!r}"
        print(f"    {key:12} {value}")
    return 0


def _cmd_example(args) -> int:
    out = pathlib.Path(args.out)
    data = examples.fig2_glossy_white(theta_s_deg=[-60, -30, 0, 30, 60, 80])
    print("Glossy white paint (paper Fig. 2 left), theta_i = 60 deg, in plane, 45-degree light:")
    print("  theta_s " + " ".join(f"{t:7.0f}" for t in data["theta_s_deg"]))
    print("  f_r     " + " ".join(f"{v:7.4f}" for v in data["fr"]))
    print("  P       " + " ".join(f"{v:7.4f}" for v in data["p"]))
    print(f"\nBaking the presets into {out / 'luts'}:")
    for name in presets.PRESETS:
        path, seconds = _bake_one(presets.preset(name), out / "luts", args, name)
        print(f"  {name:13} {path.name}  {seconds:5.2f} s")
    print(f"\nThe paper's figures from the models, in {out / 'figures'}:")
    for path in figures.all_figures(out / "figures"):
        print(f"  {path.name}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m lut",
        description="Paint LUT: physically based paint appearance from T. A. Germer's polarized light-scattering "
        "models of glossy and matte paints.",
        epilog="See README.md and docs/ for the models, the LUT format and the presets.",
    )
    parser.add_argument("--version", action="version", version=f"paint-lut {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def bake_options(p):
        p.add_argument("--out", default=DEFAULT_OUT, help="output directory (default: %(default)s)")
        p.add_argument(
            "--resolution", type=int, nargs=3, metavar=("N_U", "N_THETA_D", "N_PHI_D"),
            default=table.DEFAULT_RESOLUTION,
            help="LUT size along the half-angle, difference-angle and difference-azimuth axes (default: %(default)s)",
        )  # fmt: skip
        p.add_argument("--single-nodes", type=int, nargs=2, default=BAKE_SINGLE_NODES, metavar=("RADIAL", "AZIMUTHAL"),
                       help="quadrature of the rough single-scatter term (default: %(default)s)")  # fmt: skip
        p.add_argument("--diffuse-nodes", type=int, nargs=2, default=DIFFUSE_NODES, metavar=("RADIAL", "AZIMUTHAL"),
                       help="quadrature of the rough diffuse term (default: %(default)s)")  # fmt: skip
        p.add_argument("--force", action="store_true", help="bake even if the LUT is already in the output directory")

    ex = sub.add_parser("example", help="bake the three presets and draw the paper's Figs. 1-3 (the built-in example)")
    bake_options(ex)

    b = sub.add_parser(
        "bake",
        help="bake one paint into a LUT file",
        description="Bake a paint's polarization-averaged RGB BRDF into an EXR LUT in --out.  The file is named by "
        "the hash of its inputs: baking the same paint again costs nothing.  Give a --preset, a --paint file, or the "
        "paint's parameters as options.",
    )
    source = b.add_mutually_exclusive_group()
    source.add_argument("--preset", choices=list(presets.PRESETS), help="one of the paper's three samples")
    source.add_argument("--paint", metavar="FILE", help="a .json or .toml file of paint fields (see docs/lut.md)")
    b.add_argument("--n", type=float, help="binder refractive index (default 1.5)")
    b.add_argument(
        "--rho", nargs="+", metavar="V", help="diffuse reflectance: grey value, R G B, or a spectrum name/.csv"
    )
    b.add_argument(
        "--single", nargs="+", metavar="V", help="single-scatter weight: grey, R G B, or spectrum (default 0)"
    )
    b.add_argument("--g", type=float, help="Henyey-Greenstein asymmetry, -1 < g < 1 (default 0)")
    b.add_argument("--slope", type=float, help="RMS slope of the interface, 0 = smooth (default 0)")
    b.add_argument("--distribution", choices=["gaussian", "exponential"], help="slope distribution (default gaussian)")
    b.add_argument("--facet", type=float, help="weight of the interface reflection (default 1)")
    b.add_argument(
        "--space", choices=list(colour_management.WORKING_SPACES), help="working space (default Linear Rec.709)"
    )
    bake_options(b)

    info = sub.add_parser("info", help="print a LUT file's metadata (and verify its content hash)")
    info.add_argument("file")

    args = parser.parse_args(argv)
    if args.command == "bake":
        for key in ("rho", "single"):
            value = getattr(args, key)
            if value is not None and len(value) in (1, 3):
                try:
                    setattr(args, key, [float(v) for v in value])
                except ValueError:
                    if len(value) != 1:
                        parser.error(f"--{key} takes one grey value, three RGB values or one spectrum")
            elif value is not None:
                parser.error(f"--{key} takes one grey value, three RGB values or one spectrum")
    try:
        return {"example": _cmd_example, "bake": _cmd_bake, "info": _cmd_info}[args.command](args)
    except (ValueError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
