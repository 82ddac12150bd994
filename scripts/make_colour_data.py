"""Write lut/colour/data.py: the colour numbers a bake needs, computed with
colour-science, so that lut bakes without it (inside Blender).

    .venv/bin/python scripts/make_colour_data.py

tests/test_colour_data.py recomputes every number and fails when the file is
out of date."""

from __future__ import annotations

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut.colour import management as cm  # noqa: E402
from lut.lutfiles import files  # noqa: E402

#: colour-science collections stored whole (the presets use two of its patches).
COLLECTIONS = ("ColorChecker N Ohta",)


def build() -> str:
    colour = cm._colour()
    lines = [
        '"""Colour data for lut, computed with colour-science '
        f"{colour.__version__} by scripts/make_colour_data.py (do not edit).",
        "",
        "SPECTRAL_WEIGHTS[space]: the (3, 81) matrix of",
        "lut.colour.management.compute_spectral_weights (CIE 1931 2 degree observer,",
        "D65, 380-780 nm in 5 nm steps, Bradford to the working space).",
        "RGB_TO_RGB['A -> B']: colour-science's matrix_RGB_to_RGB with Bradford.",
        "SPECTRA['collection/name']: (wavelengths nm, values) of colour-science's",
        'colour.SDS_COLOURCHECKERS entries."""',
        "",
        "# ruff: noqa: E501",
        "# fmt: off",
        "SPECTRAL_WEIGHTS = {",
    ]
    for space in cm.WORKING_SPACES:
        rows = cm.compute_spectral_weights(space).tolist()
        lines.append(f"    {space!r}: {rows!r},")
    lines += ["}", "", "RGB_TO_RGB = {"]
    for a in cm.WORKING_SPACES:
        for b in cm.WORKING_SPACES:
            lines.append(f"    {a + ' -> ' + b!r}: {cm.compute_rgb_to_rgb(a, b).tolist()!r},")
    lines += ["}", "", "SPECTRA = {"]
    for collection in COLLECTIONS:
        for name, sd in colour.SDS_COLOURCHECKERS[collection].items():
            wl = [float(w) for w in sd.wavelengths]
            val = [float(v) for v in sd.values]
            lines.append(f"    {collection + '/' + name!r}: ({wl!r}, {val!r}),")
    lines += ["}", "# fmt: on", ""]
    return "\n".join(lines)


def main() -> int:
    target = ROOT / "lut" / "colour_data.py"
    files.atomic_write_text(target, build())
    print(f"wrote {target.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
