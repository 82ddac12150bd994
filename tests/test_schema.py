"""The paint fields' schema (lut.paint.schema) against what is derived from it:
lut.Paint, the command line's options and paint files, its limits, the
one range check and docs/lut.md.  The add-on's properties are checked
against it in test_addon.py."""

import argparse
import dataclasses
import math
import pathlib

import pytest

import lut
from lut import __main__ as cli
from lut.models import _validate
from lut.paint import schema
from lut.paint.schema import PAINT_FIELDS, Range

ROOT = pathlib.Path(__file__).resolve().parents[1]
#: The bake command's options that are not paint fields.
NOT_PAINT_OPTIONS = {
    "help",
    "preset",
    "paint",
    "out",
    "resolution",
    "single_nodes",
    "diffuse_nodes",
    "force",
    "fit",
    "eevee_mode",
}
NUMBERS = [name for name, spec in PAINT_FIELDS.items() if spec.kind in ("index", "number")]
COLOURS = [name for name, spec in PAINT_FIELDS.items() if spec.kind == "colour"]


def _bake_parser() -> argparse.ArgumentParser:
    subparsers = next(a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return subparsers.choices["bake"]


def _beyond(limits: Range):
    """Values just outside ``limits`` (between 0 and the range when 0 is allowed apart)."""
    out = []
    if limits.low is not None:
        out.append(limits.low if limits.low_open else limits.low - (limits.low / 2 if limits.zero else 1e-3))
    if limits.high is not None:
        out.append(limits.high if limits.high_open else limits.high + 1e-3)
    return out


def _within(limits: Range):
    """Values inside ``limits``: its closed ends, or points next to its open ones."""
    out = [0.0] if limits.zero else []
    if limits.low is not None:
        out.append(limits.low + (1e-3 if limits.low_open else 0.0))
    if limits.high is not None:
        out.append(limits.high - (1e-3 if limits.high_open else 0.0))
    return out


def test_the_paint_has_the_schemas_fields_and_defaults():
    assert [f.name for f in dataclasses.fields(lut.Paint)] == list(PAINT_FIELDS)
    default = lut.Paint()
    for name, spec in PAINT_FIELDS.items():
        assert getattr(default, name) == spec.default, name
        assert name in lut.Paint.__doc__
        assert spec.kind in schema.KINDS and spec.help


def test_the_command_line_options_are_the_schemas_fields():
    """Every paint field but the label is a ``bake`` option (and nothing
    else is), with the schema's help, range and choices."""
    actions = {a.dest: a for a in _bake_parser()._actions}
    options = set(actions) - NOT_PAINT_OPTIONS
    assert options == {name for name, spec in PAINT_FIELDS.items() if spec.command_line}
    assert options == set(PAINT_FIELDS) - {"name"}
    for name in options:
        spec, action = PAINT_FIELDS[name], actions[name]
        assert action.option_strings == [f"--{name}"]
        assert action.help == spec.command_line_help()
        if spec.choices:
            assert tuple(action.choices) == spec.choices
        elif spec.kind == "colour":
            assert action.nargs == "+"
        else:
            assert action.type is float
            assert spec.bake_range.text(name, _validate.REAL) in action.help


@pytest.mark.parametrize("name", NUMBERS)
def test_the_command_lines_limits_are_the_schemas(name, tmp_path, capsys):
    spec = PAINT_FIELDS[name]
    limits = spec.bake_range
    for value in _within(limits):
        args = _bake_parser().parse_args([f"--{name}", repr(value)])
        assert getattr(cli._paint_from_args(args), name) == value
    for value in _beyond(limits):
        assert cli.main(["bake", f"--{name}", repr(value), "--out", str(tmp_path)]) == 2
        noun = "" if spec.bake else _validate.REAL  # lut.Paint's own limits say what kind of value it takes
        assert capsys.readouterr().err == f"error: {schema.range_error(value, name, limits, noun=noun)}\n"
    assert not list(tmp_path.iterdir())


def test_paint_files_take_the_schemas_fields_and_nothing_else():
    data = {name: spec.default for name, spec in PAINT_FIELDS.items()}
    assert lut.Paint.from_dict(data) == lut.Paint()
    with pytest.raises(ValueError, match="unknown paint field") as error:
        lut.Paint.from_dict({**data, "gloss": 1.0})
    assert str(error.value).endswith("fields are " + ", ".join(sorted(PAINT_FIELDS)))


@pytest.mark.parametrize("name", NUMBERS + COLOURS)
def test_the_paints_limits_are_the_schemas(name):
    limits = PAINT_FIELDS[name].allowed
    for value in _within(limits):
        lut.Paint(**{name: value})
    for value in _beyond(limits) + [math.nan] + (["many"] if PAINT_FIELDS[name].kind == "number" else []):
        with pytest.raises(ValueError) as error:
            lut.Paint(**{name: value})
        assert str(error.value) == str(schema.range_error(value, name, limits))


def test_the_material_and_command_line_limits_lie_within_the_paints():
    for name, spec in PAINT_FIELDS.items():
        for narrower in (spec.material, spec.bake):
            if narrower is not None:
                assert all(v in spec.allowed for v in _within(narrower)), name


@pytest.mark.parametrize(
    ("limits", "noun", "text"),
    [
        (Range(0.0, 1.0), _validate.REAL, "x must be a real number in [0, 1], got 2.5"),
        (Range(-1.0, 1.0, low_open=True, high_open=True), _validate.REAL, "x must be a real number with -1 < x < 1"),
        (Range(-1.0, 1.0, low_open=True, high_open=True), "", "x must be in (-1, 1), got 2.5"),
        (Range(1.0, 2.0, low_open=True), "", "x must be in (1, 2], got 2.5"),
        (Range(3.0, None, low_open=True), _validate.REAL, "x must be a finite real number > 3, got 2.5"),
        (Range(None, 0.0), _validate.REAL, "x must be a finite real number <= 0, got 2.5"),
        (Range(1e-3, 2.0, zero="0 (off)"), "", "x must be 0 (off) or in [0.001, 2], got 2.5"),
    ],
)
def test_one_range_check_names_the_parameter_and_its_range(limits, noun, text):
    with pytest.raises(ValueError) as error:
        schema.check_range(2.5, "x", limits, noun=noun)
    assert str(error.value).startswith(text)
    assert schema.check_range("0.5", "x", Range(0.0, 1.0)) == 0.5
    assert schema.check_range(1.0000001, "x", Range(0.0, 1.0), tolerance=1e-6) == 1.0000001


def test_docs_list_the_schemas_fields():
    text = (ROOT / "docs" / "lut.md").read_text()
    assert schema.markdown_table() in text, "docs/lut.md: paste lut.paint.schema.markdown_table() into its field table"
