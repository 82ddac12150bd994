"""Command line of Paint LUT.

    python -m lut example [--out DIR]         bake the three presets, draw the paper's figures
    python -m lut bake --preset NAME [...]    bake one paint into a LUT file
    python -m lut info FILE [FILE ...]        describe LUT files
    python -m lut clean DIR --keep FILE ...   remove the LUTs and weights in DIR that nothing uses
    python -m lut polarized --preset NAME     render a preset's sphere polarized with Mitsuba 3 (beside pplastic)

Errors are reported as one line on standard error, with exit status 2
(130 when interrupted with Ctrl-C)."""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import json
import math
import os
import pathlib
import sys
import time
import tomllib

from . import __version__
from .colour import management as colour_management
from .lutfiles import baking, cleanup, table
from .lutfiles import format as lutfile
from .lutfiles.baking import BAKE_SINGLE_NODES
from .models.rough import DIFFUSE_NODES
from .paint import presets
from .paint.core import Paint
from .paint.schema import PAINT_FIELDS, check_range
from .render import bake as render_bake
from .render import eevee

DEFAULT_OUT = "out"
#: The largest LUT the command line bakes: N_u * N_theta_d * N_phi_d nodes
#: (256 x 128 x 128; a 50 MB file, about 150 MB of memory while baking).
MAX_NODES = 256 * 128 * 128
#: The largest quadrature size per axis (the defaults are 3 to 6).
MAX_QUADRATURE = 64
#: The paint fields the command line takes as options (and reads from paint
#: files: every field), with its limits where narrower than lut.Paint's
#: (``FieldSpec.bake``: outside them the models overflow or the LUT cannot
#: resolve the facet lobe).
OPTIONS = tuple(spec for spec in PAINT_FIELDS.values() if spec.command_line)


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


def _overrides(args) -> dict:
    """The paint fields given as options."""
    fields = {}
    for spec in OPTIONS:
        value = getattr(args, spec.name)
        if value is None:
            continue
        if spec.kind == "colour":
            value = value[0] if len(value) == 1 else tuple(value)
        fields[spec.name] = value
    return fields


def _read_paint_file(path: pathlib.Path) -> dict:
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"cannot read paint file {str(path)!r}: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"paint file {str(path)!r} is not UTF-8 text (byte {exc.start})") from None
    kind = "TOML" if path.suffix.lower() == ".toml" else "JSON"
    try:
        data = tomllib.loads(text) if kind == "TOML" else json.loads(text)
    except (tomllib.TOMLDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise ValueError(f"paint file {str(path)!r} is not valid {kind}: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"paint file {str(path)!r} must hold a table/object of paint fields")
    return data


def _paint_from_args(args) -> Paint:
    """The paint of a preset or a paint file with the options as overrides,
    or of the options alone."""
    fields = _overrides(args)
    if args.preset:
        paint = presets.preset(args.preset, args.space or colour_management.DEFAULT_SPACE)
        paint = dataclasses.replace(paint, **fields) if fields else paint
    elif args.paint:
        path = pathlib.Path(args.paint)
        data = _read_paint_file(path)
        try:
            paint = Paint.from_dict({**data, **fields})
        except ValueError as exc:
            raise ValueError(f"paint file {str(path)!r}: {exc}") from None
    else:
        paint = Paint(**fields)
    _check_limits(paint)
    return paint


def _check_limits(paint: Paint) -> None:
    """The command line's limits (``FieldSpec.bake``): beyond them the
    models overflow or the LUT cannot resolve the facet lobe.  A dispersive
    index is checked at both ends of the visible range."""
    for spec in OPTIONS:
        if spec.bake is None:
            continue
        values = [getattr(paint, spec.name)]
        if spec.kind == "index" and paint.dispersive:
            values = [float(paint.index_at(wl)) for wl in (380.0, 780.0)]
        for value in values:
            check_range(value, spec.name, spec.bake, noun="")


def _check_sizes(args) -> None:
    """Resolution and quadrature sizes the machine can bake."""
    if args.resolution is not None:
        nodes = math.prod(args.resolution)
        for name, size in zip(("N_u", "N_theta_d", "N_phi_d"), args.resolution, strict=True):
            if not 2 <= size <= 4096:
                raise ValueError(
                    f"--resolution: {name} must be a whole number in [2, 4096], got {size} "
                    f"(in {' '.join(map(str, args.resolution))})"
                )
        if nodes > MAX_NODES:
            raise ValueError(
                f"--resolution must be three whole numbers >= 2 with a product N_u*N_theta_d*N_phi_d of at most "
                f"{MAX_NODES} (e.g. 256 128 128), got {' '.join(map(str, args.resolution))} ({nodes} nodes)"
            )
    for key in ("single_nodes", "diffuse_nodes"):
        value = getattr(args, key, None)
        if value is not None and not all(1 <= v <= MAX_QUADRATURE for v in value):
            option = "--" + key.replace("_", "-")
            raise ValueError(f"{option} must be two whole numbers in [1, {MAX_QUADRATURE}], got {list(value)}")


def _check_out(out) -> None:
    """The output folder: a folder (made when missing) that can be written,
    checked before any work."""
    out = pathlib.Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out must be a folder, got a file: {out}")
    existing = next((p for p in (out, *out.parents) if p.exists()), None)
    if existing is not None and not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"--out {out}: cannot write into {existing} (permission denied)")


def _cmd_bake(args) -> int:
    _check_sizes(args)
    _check_out(args.out)
    paint = _paint_from_args(args)
    path, seconds = _bake_one(paint, args.out, args, paint.name or "bake")
    print(f"{path}  ({seconds:.2f} s)")
    # The LUT holds the paint type; the colours are the renderer's inputs.
    rbar = baking.load_lut(path).internal_reflectance
    for name, value in render_bake.node_inputs(paint, rbar).items():
        shown = value if isinstance(value, float) else "(" + ", ".join(f"{v:.6g}" for v in value) + ")"
        print(f"  {name}: {shown}")
    if args.fit:
        _print_fits(paint, args)
    return 0


def _print_fits(paint, args) -> None:
    """Fit the baked type for Cycles and EEVEE (the newest calibrated
    Blender line) and print the fidelity measure each fit reports for the
    paint, whole and over the grazing band, with the goals."""
    calibration = max(eevee.available_versions(), default=None)
    options = {k: getattr(args, k) for k in ("resolution", "single_nodes", "diffuse_nodes")}
    result = render_bake.bake_for_render(
        paint, args.out, eevee_calibration=calibration, eevee_mode=args.eevee_mode, **options
    )
    for target, (whole, grazing) in result.all_errors(paint).items():
        fit = result.fits[target]
        goals = fit.goals
        misses = whole > goals[0] or grazing > goals[1]
        drawn = ""
        if target == "EEVEE":
            exact = fit.sums_exactly
            # As the panel has it: the type's noisiest colour, down to this colour's error.
            samples = eevee.samples_for(eevee.type_spread(fit), max(whole, eevee.NOISE_FLOOR))
            drawn = ", exact at 1 sample" if exact else f", converged: about {samples} samples"
        print(
            f"  {target.title()} fit: {100 * whole:.2f}% (goal {100 * goals[0]:.0f}%), grazing light"
            f" {100 * grazing:.2f}% (goal {100 * goals[1]:.0f}%){drawn}{'  MISSES' if misses else ''}"
        )


def _cmd_info(args) -> int:
    status = 0
    for i, file in enumerate(args.file):
        try:
            _, header = lutfile.read(file)  # verifies the content hash
        except (ValueError, OSError) as exc:
            if len(args.file) == 1:
                raise
            print(f"error: {exc}", file=sys.stderr)
            status = 2
            continue
        if i:
            print()
        _print_info(file, header)
        named = cleanup.file_key(file)
        if named is not None and not header["key"].startswith(named):
            print(
                f"error: {file}: its name says key {named} but it holds the LUT of key {header['key'][:24]} "
                "(copied or renamed from another paint type's file)",
                file=sys.stderr,
            )
            status = 2
    return status


def _print_info(file, header) -> None:
    meta = header["meta"]
    width, height, channels = header["size"]
    print(f"{file}: Paint LUT format {meta['format']}, {width}x{height} pixels, {channels} channels (Non-Color)")
    print(f"  components      {', '.join(meta['components'])} (tiles: {meta['tiles']})")
    print(f"  internal refl.  {meta['internal_reflectance']:.6f} (r-bar: k(rho) = rho (1 - r-bar)/(1 - rho r-bar))")
    print(f"  resolution      {meta['resolution']} (N_u, N_theta_d, N_phi_d)")
    print(f"  parameterization {meta['parameterization']}")
    for key in ("single_nodes", "diffuse_nodes"):
        if key in meta:
            print(f"  {key:15} {meta[key]}")
    print(f"  content hash    {header['hash']} (verified)")
    print(f"  key             {header['key']}")
    print("  paint type (every colour of it shares this LUT):")
    for key, value in meta["type"].items():
        if isinstance(value, dict):
            value = f"spectrum {value.get('spectrum')!r}"
        print(f"    {key:12} {value}")


def _cmd_clean(args) -> int:
    removed = cleanup.clean(args.directory, keep=args.keep, dry_run=args.dry_run)
    verb = "would remove" if args.dry_run else "removed"
    for path in removed:
        print(f"{verb} {path}")
    print(f"{verb} {len(removed)} file(s) from {args.directory}")
    return 0


#: The polarized command's limits: image side in pixels, samples per pixel.
POLARIZED_SIZE = (8, 2048)
POLARIZED_SPP = (1, 4096)


def _cmd_polarized(args) -> int:
    """Render a preset's sphere polarized (``lut.polarized.pictures``)."""
    for name, value, (low, high) in (("size", args.size, POLARIZED_SIZE), ("spp", args.spp, POLARIZED_SPP)):
        if not low <= value <= high:
            raise ValueError(f"--{name} must be an integer in [{low}, {high}], got {value}")
    if importlib.util.find_spec("mitsuba") is None:  # not imported: DRJIT_LIBLLVM_PATH is read at import
        raise ValueError(
            "the polarized command needs Mitsuba 3, which is in its own environment: run "
            "`.venv-mitsuba/bin/python -m lut polarized ...` (scripts/bootstrap.sh makes .venv-mitsuba)"
        )
    from .polarized import mitsuba_bsdf, pictures

    out = pathlib.Path(args.out)
    _check_out(out)
    try:
        variant, why = mitsuba_bsdf.choose_variant()
        print(why)
        paint = presets.preset(args.preset)
        rendered = pictures.render(
            paint, size=args.size, spp=args.spp, cache=out / "mueller", pplastic=not args.no_pplastic, variant=variant
        )
    except RuntimeError as exc:  # Mitsuba reports its own and its plugins' errors as RuntimeError
        raise ValueError(str(exc).strip().splitlines()[-1]) from None
    for name, seconds in rendered["seconds"].items():
        print(f"  {name}: rendered in {seconds:.2f} s ({args.size}x{args.size}, {args.spp} spp)")
    title = f"{args.preset}: a sphere under a sun and a sky, {variant}"
    for path in pictures.write(out, args.preset, rendered, title):
        print(path)
    return 0


def _cmd_example(args) -> int:
    try:  # development modules: the extension's wheel leaves them out
        from . import examples, figures
    except ImportError as error:
        raise SystemExit(
            f"error: the example command needs the repository's lut (examples, figures): {error}"
        ) from None
    _check_sizes(args)
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


def build_parser() -> argparse.ArgumentParser:
    """The command line's parser (its ``bake`` options: ``OPTIONS``)."""
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
    for spec in OPTIONS:  # the paint's fields (lut.paint.schema)
        if spec.kind == "colour":
            kind = {"nargs": "+", "metavar": "V"}
        elif spec.choices:
            kind = {"choices": list(spec.choices)}
        else:
            kind = {"type": float}
        b.add_argument(f"--{spec.name}", help=spec.command_line_help(), **kind)
    bake_options(b)
    b.add_argument(
        "--fit",
        action="store_true",
        help="also fit the closures of Cycles and EEVEE and print the fidelity measure each reports for the paint"
        " (whole and grazing light, with the goals)",
    )
    b.add_argument(
        "--eevee-mode",
        choices=render_bake.fitting.EEVEE_MODES,
        default=render_bake.fitting.DEFAULT_EEVEE_MODE,
        help="with --fit: EEVEE's fit exact at one sample, or converged over samples (more closures where the"
        " exact one misses its goal; default %(default)s)",
    )

    parser.bake_parser = b  # its own usage line for errors found after parsing
    info = sub.add_parser("info", help="print LUT files' metadata (and verify their content hashes)")
    info.add_argument("file", nargs="+")

    clean = sub.add_parser(
        "clean",
        help="remove the LUTs and weights files in a directory that nothing uses",
        description="Remove from DIR the LUT files (paintlut-*.exr) not given with --keep, their closure weights "
        "(paintfit-*.exr), and the temporary files of interrupted writes.  Other files are never touched.",
    )
    clean.add_argument("directory", metavar="DIR")
    clean.add_argument(
        "--keep", nargs="*", default=[], metavar="FILE", help="LUT files still in use (kept with their weights)"
    )
    clean.add_argument("--dry-run", action="store_true", help="only list what would be removed")

    pol = sub.add_parser(
        "polarized",
        help="render a preset's sphere polarized with Mitsuba 3, beside Mitsuba's pplastic (needs .venv-mitsuba)",
        description="Render a sphere of a preset paint under a sun and a sky with the Mitsuba 3 plugin germer_paint "
        "(and with Mitsuba's pplastic given the same paint), and write its Stokes images (EXR, S0..S3) and one "
        "figure: S0, the degree of linear polarization and its angle.  Runs in .venv-mitsuba.",
    )
    pol.add_argument("--preset", choices=list(presets.PRESETS), default="green_carc", help="default: %(default)s")
    pol.add_argument("--out", default=str(pathlib.Path(DEFAULT_OUT) / "polarized"), help="default: %(default)s")
    pol.add_argument("--size", type=int, default=128, help="image side in pixels (default: %(default)s)")
    pol.add_argument("--spp", type=int, default=16, help="samples per pixel (default: %(default)s)")
    pol.add_argument("--no-pplastic", action="store_true", help="render germer_paint only")

    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "bake":
        for key in (spec.name for spec in OPTIONS if spec.kind == "colour"):
            value = getattr(args, key)
            if value is not None and len(value) in (1, 3):
                try:
                    setattr(args, key, [float(v) for v in value])
                except ValueError:
                    if len(value) != 1:
                        parser.bake_parser.error(f"--{key} takes one grey value, three RGB values or one spectrum")
            elif value is not None:
                parser.bake_parser.error(f"--{key} takes one grey value, three RGB values or one spectrum")
    command = {
        "example": _cmd_example,
        "bake": _cmd_bake,
        "info": _cmd_info,
        "clean": _cmd_clean,
        "polarized": _cmd_polarized,
    }[args.command]
    try:
        return command(args)
    except (ValueError, OSError) as exc:
        if isinstance(exc, BrokenPipeError):
            return _broken_pipe()
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


def _broken_pipe() -> int:
    """The reader of our output went away (``... | head``): stop quietly.
    Python would report the failed flush of stdout at exit; point it at
    /dev/null first."""
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), sys.stdout.fileno())
    except (AttributeError, OSError, ValueError):
        pass  # stdout is not a file (tests)
    return 141  # as a shell reports a process ended by SIGPIPE


def run() -> int:
    """``main`` with the output flushed while a closed pipe can still be
    handled (``python -m lut info ... | head``)."""
    try:
        status = main()
        sys.stdout.flush()
    except BrokenPipeError:
        return _broken_pipe()
    except KeyboardInterrupt:  # outside a command: while importing or parsing
        print("interrupted", file=sys.stderr)
        return 130
    return status


if __name__ == "__main__":
    sys.exit(run())
