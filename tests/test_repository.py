"""The README's two set-up commands exist and CI runs them."""

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _readme_commands():
    readme = (ROOT / "README.md").read_text()
    return re.findall(r"^(bash scripts/bootstrap\.sh && .+)$", readme, flags=re.M)


def test_readme_has_an_example_command_and_a_test_command():
    commands = _readme_commands()
    assert any("-m lut example" in c for c in commands)
    assert any(c.endswith("bash scripts/test.sh") for c in commands)
    test_sh = (ROOT / "scripts" / "test.sh").read_text()
    assert ".venv/bin/python -m pytest" in test_sh  # every test, under Blender 5.0's environment
    assert ".venv-mitsuba/bin/python -m pytest" in test_sh  # the Mitsuba plugin's, in its own


def test_ci_runs_the_readme_commands():
    ci = (ROOT / ".ci" / "run").read_text()
    for command in _readme_commands():
        assert command in ci, f"CI does not run the README command: {command}"


def test_readme_pictures_and_scripts_exist():
    """Everything the README shows is in the repository (made by its scripts)."""
    readme = (ROOT / "README.md").read_text()
    pictures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", readme)
    assert "docs/figures/presets.png" in pictures
    scripts = set(re.findall(r"scripts/[a-z_]+\.(?:py|sh)", readme))
    assert {"scripts/build_extension.py", "scripts/batch_bake.py", "scripts/render_fidelity.py"} <= scripts
    missing = [p for p in [*pictures, *scripts] if not (ROOT / p).is_file()]
    assert not missing, missing


def test_scripts_never_write_the_documented_pictures_by_default():
    """A trial run of a picture script leaves docs/figures alone (the docs
    give --out for the real ones), and the model benchmark compares only
    timings it takes itself."""
    for script in ("render_presets.py", "figures.py"):
        source = (ROOT / "scripts" / script).read_text()
        (default,) = re.findall(r'"--out", default=([^,)]+)', source)
        assert "docs" not in default, (script, default)
    assert not (ROOT / "scripts" / "data" / "scatmech_speed.json").exists()
    assert "scatmech_cost(" in (ROOT / "scripts" / "benchmark_models.py").read_text()
