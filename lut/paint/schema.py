"""The fields of a paint, each described once: ``PAINT_FIELDS``.

A ``FieldSpec`` gives a ``lut.Paint`` field's kind, default, help text and
allowed range, and, where narrower, the limits of the material's panel field
in Blender (hard limits, and the slider's soft ones) and of the command line.
Everything else is derived from it:

- ``lut.Paint``: its fields' defaults, validation and docstring;
- the command line (lut/__main__.py): the ``bake`` options (names, types,
  help), the paint file keys it reads, and its limits;
- the add-on: the material's properties (limits, slider, tooltip; Blender
  stores them, addon/properties.py) and the check that a paint fits them
  (addon/validation.py);
- the table of fields in docs/lut.md (``markdown_table``; a test keeps it
  current).

Adding a field to a paint is a ``FieldSpec`` here and its physics in
lut/paint/core.py.  Every paint field is dimensionless (an index, reflectances,
weights, a slope): no field has a unit."""

from __future__ import annotations

import dataclasses
from typing import Any

from ..colour import management as cm
from ..models import _validate
from ..models._validate import Range, check_range, range_error  # noqa: F401  (the command line's and add-on's)

#: The kinds of field: how a value is given, checked, shown and stored.
#: ``index`` a number, or Cauchy coefficients in a spectral paint;
#: ``colour`` an RGB triple, a grey number or a spectrum, each value in
#: ``allowed``; ``number`` a real number; ``choice`` one of ``choices``;
#: ``text`` a label.
KINDS = ("index", "colour", "number", "choice", "text")


@dataclasses.dataclass(frozen=True)
class FieldSpec:
    """One field of ``lut.Paint``.

    name        the field's (and the command line option's, and the TOML key's) name
    kind        one of ``KINDS``
    default     the value a paint gets without it
    help        what the field means (docs, command line help)
    allowed     what ``lut.Paint`` accepts (for a colour: each value)
    choices     the values of a choice
    label       the panel field's name in Blender ('' : not on a material);
                a colour's label is also the node group input that shows it
    tooltip     the panel field's description (default: ``help``)
    material    the panel field's hard limits, where narrower than ``allowed``:
                Blender clamps beyond them, so ``addon.validation`` refuses
                a paint outside them
    soft        the panel slider's (soft_min, soft_max), where narrower
    precision   digits the panel shows (None: Blender's default)
    bake        the command line's limits, where narrower than ``allowed``
    command_line whether ``python -m lut bake`` takes it as an option
    shapes_type whether it shapes the paint type (its LUT): a change needs a bake
    """

    name: str
    kind: str
    default: Any
    help: str
    allowed: Range | None = None
    choices: tuple[str, ...] = ()
    label: str = ""
    tooltip: str = ""
    material: Range | None = None
    soft: tuple[float | None, float | None] = (None, None)
    precision: int | None = None
    bake: Range | None = None
    command_line: bool = True
    shapes_type: bool = False

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"FieldSpec {self.name}: kind must be one of {', '.join(KINDS)}, got {self.kind!r}")

    @property
    def on_material(self) -> bool:
        """Whether a material stores it as a panel field."""
        return bool(self.label)

    @property
    def material_range(self) -> Range | None:
        """The panel field's hard limits (``allowed`` unless narrower)."""
        return self.material or self.allowed

    @property
    def bake_range(self) -> Range | None:
        """The command line's limits (``allowed`` unless narrower)."""
        return self.bake or self.allowed

    def check(self, value) -> float:
        """A number (or one colour value) of the field, checked against
        ``allowed``: ValueError naming the field and its range."""
        return check_range(value, self.name, self.allowed)

    def default_text(self) -> str:
        """The default as help and docs show it: "1.5", "0.8 grey", "gaussian"."""
        value = self.default
        if isinstance(value, tuple):
            if len(set(value)) == 1:
                return f"{value[0]:g} grey" if value[0] else "0"
            return " ".join(f"{v:g}" for v in value)
        if isinstance(value, float):
            return f"{value:g}"
        return str(value) if value else "''"

    def allowed_text(self) -> str:
        """What the field accepts: an interval ("[0, 1]", "> 0") or the choices."""
        if self.choices:
            return ", ".join(f"`{c}`" for c in self.choices)
        return self.allowed.interval() if self.allowed else ""

    def command_line_help(self) -> str:
        """The ``bake`` option's help."""
        limits = ""
        if self.kind in ("index", "number") and self.bake_range is not None:
            limits = f"; {self.bake_range.text(self.name, 'a real number')}"
        return f"{self.help}{limits}; default {self.default_text()}".replace("%", "%%")


_DISTRIBUTIONS = tuple(_validate.DISTRIBUTIONS)

#: The fields of ``lut.Paint``, in its order.
PAINT_FIELDS: dict[str, FieldSpec] = {
    spec.name: spec
    for spec in (
        FieldSpec(
            "n", "index", 1.5,
            "binder refractive index; a spectral paint's (in Python or a paint file) may be Cauchy coefficients "
            "(A, B, C, D): n(λ) = A + B/λ² + … with λ in µm",
            allowed=_validate.INDEX, label="Index", tooltip="Refractive index of the binder",
            material=Range(1.0, 4.0), soft=(None, 2.0), precision=3, bake=Range(1.0, 4.0), shapes_type=True,
        ),
        FieldSpec(
            "rho", "colour", (0.8, 0.8, 0.8),
            "diffuse subsurface reflectance: grey value, R G B, or a spectrum (dataset name or .csv)",
            allowed=_validate.REFLECTANCE, label="Pigment Color",
            tooltip="Reflectance rho of the multiply scattering pigment under the binder (scene-linear RGB); "
            "changes render at once, no bake",
        ),
        FieldSpec(
            "single", "colour", (0.0, 0.0, 0.0),
            "weight of the single-scatter term: grey, R G B, or a spectrum (the paper's Eq. 20 has none: 1 is "
            "the paper's model)",
            allowed=_validate.REFLECTANCE, label="Single Scattering Color",
            tooltip="Albedo of single scattering by pigment particles under the surface; changes render at once",
        ),
        FieldSpec(
            "g", "number", 0.0, "Henyey-Greenstein asymmetry of single scattering (positive: forward)",
            allowed=_validate.ASYMMETRY, label="Anisotropy", material=Range(-0.99, 0.99), shapes_type=True,
        ),
        FieldSpec(
            "slope", "number", 0.0, "total RMS slope of the interface (0: smooth)",
            allowed=_validate.SLOPE, label="Roughness Slope",
            tooltip="RMS slope of the surface (0: smooth, glossy; 2: very matte)",
            material=Range(0.0, 3.0), soft=(None, 1.0), precision=3, shapes_type=True,
            # A narrower facet lobe than 0.001 is not resolved by any LUT the command line bakes.
            bake=Range(1e-3, 3.0, zero="0 (smooth)"),
        ),
        FieldSpec(
            "distribution", "choice", "gaussian", "slope distribution of the interface",
            choices=_DISTRIBUTIONS, label="Slopes", tooltip="Distribution of the surface's slopes", shapes_type=True,
        ),
        FieldSpec(
            "facet", "number", 1.0, "weight of the interface (facet) reflection",
            allowed=Range(0.0, None), label="Surface Reflection",
            tooltip="Weight of the reflection by the surface itself; changes render at once",
            material=Range(0.0, 1.0),
        ),
        FieldSpec(
            "space", "choice", cm.DEFAULT_SPACE, "working space of RGB values and of the results",
            choices=tuple(cm.WORKING_SPACES),
        ),
        FieldSpec("name", "text", "", "a label; not part of the physics or of the cache key", command_line=False),
    )
}  # fmt: skip


def markdown_table() -> str:
    """The table of paint fields in docs/lut.md."""
    rows = [
        "| field | meaning | allowed | on a material (panel) | command line | default |",
        "|---|---|---|---|---|---|",
    ]
    for spec in PAINT_FIELDS.values():
        panel = ""
        if spec.on_material:
            panel = spec.material_range.interval() if spec.material_range else ""
            low, high = spec.soft
            slider = ([f"from {low:g}"] if low is not None else []) + ([f"up to {high:g}"] if high is not None else [])
            if slider:
                panel += ", slider " + " ".join(slider)
            panel = f"{spec.label}: {panel}" if panel else spec.label
        if not spec.command_line:
            line = "—"
        elif spec.bake:
            line = spec.bake.interval()
        else:
            line = "as allowed"
        help_ = spec.help.replace("|", "\\|")
        rows.append(
            f"| `{spec.name}` | {help_} | {spec.allowed_text()} | {panel or '—'} | {line} | {spec.default_text()} |"
        )
    return "\n".join(rows)
