"""The command line: python -m lut example | bake | info."""

import re
import subprocess
import sys

import pytest

from lut.__main__ import main

SMALL = ["--resolution", "8", "6", "4"]


def test_example_bakes_the_presets_and_draws_the_figures(tmp_path, capsys):
    assert main(["example", "--out", str(tmp_path), *SMALL]) == 0
    out = capsys.readouterr().out
    for name in ("glossy_white", "glossy_red", "green_carc"):
        assert name in out
    assert len(list((tmp_path / "luts").glob("paintlut-*.exr"))) == 3
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == [
        "fig1.png",
        "fig2_red.png",
        "fig2_white.png",
        "fig3_carc.png",
    ]


def test_bake_from_options_toml_and_json_then_info(tmp_path, capsys):
    assert (
        main(["bake", "--rho", "0.7", "0.3", "0.1", "--single", "0.2", "--g", "0.4", "--out", str(tmp_path), *SMALL])
        == 0
    )
    first = capsys.readouterr().out.split()[0]
    toml = tmp_path / "paint.toml"
    toml.write_text('rho = [0.7, 0.3, 0.1]\nsingle = 0.2\ng = 0.4\nname = "same paint"\n')
    assert main(["bake", "--paint", str(toml), "--out", str(tmp_path), *SMALL]) == 0
    assert capsys.readouterr().out.split()[0] == first  # the same paint: the same (cached) file
    json_file = tmp_path / "paint.json"
    json_file.write_text('{"rho": "ColorChecker N Ohta/red", "slope": 0.2}')
    assert main(["bake", "--paint", str(json_file), "--out", str(tmp_path), *SMALL]) == 0
    second = capsys.readouterr().out.split()[0]
    assert second != first
    assert main(["info", second]) == 0
    info = capsys.readouterr().out
    assert "content hash" in info and "(verified)" in info and "paint type" in info and "slope        0.2" in info
    # The LUT has no colour: a preset in another working space bakes the same
    # type; only the printed colour inputs (in that space) differ.
    assert main(["bake", "--preset", "glossy_white", "--out", str(tmp_path), *SMALL]) == 0
    rec709 = capsys.readouterr().out
    assert main(["bake", "--preset", "glossy_white", "--space", "ACEScg", "--out", str(tmp_path), *SMALL]) == 0
    aces = capsys.readouterr().out
    assert aces.split()[0] == rec709.split()[0]
    assert "Pigment Color" in aces and aces.split("\n")[1:] != rec709.split("\n")[1:]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["bake", "--rho", "2"], "error: rho must be a real number in [0, 1], got 2.0"),
        (["bake", "--slope", "-1"], "error: slope must be a finite real number >= 0"),
        (["bake", "--paint", "missing.toml"], "error: cannot read paint file 'missing.toml'"),
        (["info", "missing.exr"], "error: missing.exr: no such LUT file"),
        (["polarized", "--size", "4"], "error: --size must be an integer in [8, 2048], got 4"),
        (["polarized", "--spp", "0"], "error: --spp must be an integer in [1, 4096], got 0"),
    ],
)
def test_errors_are_one_line(argv, message, tmp_path, capsys):
    out = ["--out", str(tmp_path)] if argv[0] in ("bake", "polarized") else []
    assert main([*argv[:1], *argv[1:], *out]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(message) and "\n" not in err


def test_the_polarized_command_says_where_mitsuba_is_when_it_is_not_here(tmp_path, capsys):
    try:
        import mitsuba  # noqa: F401
    except ImportError:
        pass
    else:
        pytest.skip("mitsuba is installed here (tests/test_mitsuba_plugin.py runs the command)")
    assert main(["polarized", "--out", str(tmp_path), "--size", "8"]) == 2
    assert ".venv-mitsuba/bin/python -m lut polarized" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())  # nothing written


def test_bad_toml_and_help(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("rho = [0.1,\n")
    assert main(["bake", "--paint", str(bad), "--out", str(tmp_path)]) == 2
    assert "is not valid TOML" in capsys.readouterr().err
    run = subprocess.run([sys.executable, "-m", "lut", "bake", "--help"], capture_output=True, text=True)
    assert run.returncode == 0 and "--preset" in run.stdout and "hash of its inputs" in run.stdout


def test_bake_with_fit_reports_the_fidelity_measure_of_each_engine(tmp_path, capsys):
    """``lut bake --fit``: the fidelity measure each engine's fit reports for
    the paint, whole and over the grazing band, equal to the library's own
    figures, with the goals; a miss is marked."""
    import re

    import lut
    from lut.render import bake as render_bake

    assert main(["bake", "--preset", "glossy_red", "--out", str(tmp_path), "--fit"]) == 0
    out = capsys.readouterr().out
    lines = {m[0]: (float(m[1]), float(m[2]), "MISSES" in m[3]) for m in re.findall(
        r"(Cycles|Eevee) fit: ([\d.]+)% \(goal \d+%\), grazing light ([\d.]+)% \(goal \d+%\)(.*)", out
    )}  # fmt: skip
    assert set(lines) == {"Cycles", "Eevee"}
    paint = lut.preset("glossy_red")
    result = render_bake.bake_for_render(paint, tmp_path, eevee_calibration=(5, 2))
    for target, (whole, grazing) in result.all_errors(paint).items():
        shown = lines[target.title()]
        assert shown[:2] == pytest.approx((100 * whole, 100 * grazing), abs=0.006)
        goals = result.fits[target].goals
        assert shown[2] == (whole > goals[0] or grazing > goals[1])
    exact = result.fits["EEVEE"].sums_exactly
    assert re.search(r"Eevee fit: .*(, exact at 1 sample|, converged: about \d+ samples)", out)
    assert (", exact at 1 sample" in out) == exact


def test_bake_with_fit_draws_eevee_in_the_mode_asked(tmp_path, capsys):
    """``--eevee-mode``: a sharp exponential paint, which EEVEE's three
    exact closures miss, converges over samples by default and is exact at
    one sample when asked; an unknown mode is refused by name."""
    args = ["bake", "--out", str(tmp_path), "--fit", "--slope", "0.0785", "--distribution", "exponential"]
    args += ["--n", "1.735", "--rho", "0.0926", "0.0141", "0.017", "--single", "0.0705", "0.2976", "0.0487"]
    args += ["--g", "0.41", "--facet", "0.677"]  # random_paints(24)[21]: exact 24.9%, converged 8.8%
    assert main(args) == 0
    assert re.search(r"Eevee fit: .*, converged: about \d+ samples", capsys.readouterr().out)
    assert main([*args, "--eevee-mode", "EXACT"]) == 0
    assert ", exact at 1 sample" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main([*args, "--eevee-mode", "FAST"])
    assert "--eevee-mode: invalid choice: 'FAST'" in capsys.readouterr().err
