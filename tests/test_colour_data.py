"""lut.colour.data: the stored colour numbers equal colour-science's, and lut
bakes spectral presets without colour-science (as inside Blender)."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from lut.colour import data as colour_data
from lut.colour import management as cm

colour = pytest.importorskip("colour")


@pytest.mark.parametrize("space", list(cm.WORKING_SPACES))
def test_spectral_weights_are_colour_science(space):
    np.testing.assert_allclose(cm.spectral_weights(space), cm.compute_spectral_weights(space), rtol=0, atol=1e-15)


@pytest.mark.parametrize("a", list(cm.WORKING_SPACES))
@pytest.mark.parametrize("b", list(cm.WORKING_SPACES))
def test_rgb_to_rgb_is_colour_science(a, b):
    rgb = np.array([0.2, 0.5, 0.7])
    expected = colour.RGB_to_RGB(
        rgb, cm.WORKING_SPACES[a], cm.WORKING_SPACES[b], chromatic_adaptation_transform="Bradford"
    )
    np.testing.assert_allclose(cm.rgb_to_rgb(a, b) @ rgb, expected, rtol=0, atol=1e-14)


def test_stored_spectra_are_colour_science():
    for key, (wavelengths, values) in colour_data.SPECTRA.items():
        collection, _, name = key.partition("/")
        sd = colour.SDS_COLOURCHECKERS[collection][name]
        np.testing.assert_array_equal(wavelengths, sd.wavelengths)
        np.testing.assert_array_equal(values, sd.values)


def test_presets_bake_without_colour_science(tmp_path):
    """Block `import colour` in a fresh interpreter: presets still build and
    bake, and a spectrum that is not stored asks for colour-science by name."""
    code = textwrap.dedent(
        f"""
        import sys
        sys.modules["colour"] = None  # import colour -> ImportError
        import lut
        for name in lut.PRESETS:
            paint = lut.preset(name, "ACEScg")
            lut.bake(paint, {str(tmp_path)!r}, resolution=(8, 4, 3))
        try:
            lut.Spectrum("ColorChecker 2005/red")
        except ValueError as exc:
            assert "needs colour-science" in str(exc), exc
        else:
            raise AssertionError("no error")
        assert "colour" not in sys.modules or sys.modules["colour"] is None
        print("ok")
        """
    )
    run = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=str(cm.pathlib.Path(__file__).parents[1])
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "ok"
