"""The fidelity measure on pixel samples (lut.bench.binned_error) and, with
bpy, the EEVEE and Cycles renders of a randomised set of paints measured
with it (scripts/eevee_fidelity.py: every paint on its own sphere, one sweep
of light angles)."""

import numpy as np
import pytest

from lut import bench
from lut.render import measure


def _samples(count=20000, seed=3):
    rng = np.random.default_rng(seed)
    tl = rng.uniform(0, np.radians(80), count)
    tv = rng.uniform(0, np.radians(80), count)
    ph = rng.uniform(-np.pi, np.pi, count)
    model = np.stack([np.cos(tl) * (1 + np.cos(ph) * np.sin(tv))] * 3, axis=-1)
    return tl, tv, ph, model


def test_binned_error_is_the_relative_rms_of_bin_means():
    tl, tv, ph, model = _samples()
    assert bench.binned_error(tl, tv, ph, model, model)[0] == 0.0
    # A uniform 10% excess is a 10% error, whatever the binning.
    assert bench.binned_error(tl, tv, ph, 1.1 * model, model)[0] == pytest.approx(0.1, rel=1e-12)
    # Noise that averages out within bins hardly counts; a bias does.
    rng = np.random.default_rng(0)
    noisy = model * (1 + 0.05 * rng.choice([-1.0, 1.0], model.shape))
    assert bench.binned_error(tl, tv, ph, noisy, model)[0] < 0.03


def test_binned_error_leaves_out_the_mirror_and_what_the_measure_does_not_cover():
    tl, tv, ph, model = _samples()
    near = bench.mirror_distance(tl, tv, ph) < bench.MIRROR_DISTANCE
    off_range = (tl > np.radians(78)) | (tv > np.radians(78)) | (tv < np.radians(2))
    assert near.any() and off_range.any()
    spoiled = np.where((near | off_range)[:, None], 100 * model, model)
    assert bench.binned_error(tl, tv, ph, spoiled, model)[0] == 0.0
    # A rough paint has no mirror to leave out: the measure counts it.
    assert bench.binned_error(tl, tv, ph, spoiled, model, smooth=False)[0] > 1.0
    off = np.where(off_range[:, None], 100 * model, model)
    assert bench.binned_error(tl, tv, ph, off, model, smooth=False)[0] == 0.0
    assert bench.mirror_distance(0.3, 0.3, 0.0) == pytest.approx(0.0, abs=1e-7)
    assert bench.mirror_distance(0.0, 0.2, 1.0) == pytest.approx(0.2)
    with pytest.raises(ValueError, match="no bin"):
        bench.binned_error(tl[:2], tv[:2], ph[:2], model[:2], model[:2])


@pytest.mark.parametrize("smooth", [True, False])
def test_binned_error_on_the_measures_geometries_is_the_measure(smooth):
    """One sample at each of the measure's geometries (its bin centres, φ
    from 0 to 180°): binned_error is ``measure.relative_rms`` over them,
    every geometry counted once (no cos θl weight), the mirror's
    neighbourhood left out for a smooth paint only."""
    tl, tv, ph = measure.points(smooth)
    model = np.stack([np.cos(tl) * (1 + np.cos(ph) * np.sin(tv)), np.cos(tv), 0.5 + 0 * tl], axis=-1)
    rendered = model * (1 + 0.2 * np.random.default_rng(5).standard_normal(model.shape))
    error, bins = bench.binned_error(tl, tv, ph, rendered, model, min_pixels=1, smooth=smooth)
    assert bins == tl.size
    assert error == pytest.approx(measure.relative_rms(rendered, model), rel=1e-12)
    whole, grazing, _ = bench.binned_errors(tl, tv, ph, rendered, model, min_pixels=1, smooth=smooth)
    assert (whole, grazing) == pytest.approx(measure.errors(rendered, model, tl), rel=1e-12)
    # Far from the normal (θl = 75°) counts as much as near it: an error
    # there alone is not scaled down by cos θl.
    grazing = np.where((tl > np.radians(70))[:, None], 1.1 * model, model)
    want = 0.1 * np.sqrt(np.sum(model[tl > np.radians(70)] ** 2) / np.sum(model**2))
    got = bench.binned_error(tl, tv, ph, grazing, model, min_pixels=1, smooth=smooth)[0]
    assert got == pytest.approx(want, rel=1e-12)


@pytest.fixture(scope="module")
def randomised(addon_registered, tmp_path_factory):
    """The first 12 paints of the randomised set (3 smooth, 9 rough, dark and
    light, both slope distributions, both signs of g) on spheres, rendered by
    EEVEE and Cycles over the sweep of light angles."""
    pytest.importorskip("bpy")
    from scripts import eevee_fidelity

    paints = bench.random_paints(12)
    return eevee_fidelity.measure(paints, tmp_path_factory.mktemp("luts"), cycles=True)


@pytest.mark.render
def test_cycles_renders_every_paint_within_its_target_on_the_dense_measure(randomised):
    """Every pixel of the spheres, binned on the fidelity measure's grid:
    within the Cycles goals (``measure.goals``), whole and over the grazing
    band, or, where the fit reports a miss (the Gaussian slope 2.88: rougher
    than any Blender lobe), near what it reports."""
    for row in randomised:
        goals = measure.goals("CYCLES", row["paint"].slope == 0)
        for band, goal in zip(("", "_grazing"), goals, strict=True):
            reported = row["cycles_fit" + band]
            bound = goal if reported <= goal else 1.5 * reported
            assert row["cycles" + band] <= bound, (row["label"], band, row["cycles" + band], reported)


@pytest.mark.render
def test_eevee_renders_the_randomised_set_as_measured(randomised):
    """EEVEE's exact fits (the scene's EEVEE mode Exact at 1 sample: one
    sample, its own closure approximations, at most two exact reflection
    lobes; the viewport's Material Preview and a final EEVEE render are the
    same engine) against the model: bounds a little above
    what this set measures on Blender 5.0 and 5.2 (README), so a broken
    calibration, fit or texture lookup shows.  Smooth paints: the median
    within 5%; rough: the median within 16%; none beyond 45%.  And the error
    the fit reports (the panel's, on the measure's grid) is not far below
    the render's: within 1.6 times it plus 2%."""
    smooth = [r["eevee"] for r in randomised if r["paint"].slope == 0]
    rough = [r["eevee"] for r in randomised if r["paint"].slope > 0]
    assert len(smooth) >= 3 and len(rough) >= 9
    # On the fidelity measure (no cos θl weight: grazing light in full) this
    # set's smooth paints measured 3.5%, 4.2% and 5.4% on Blender 5.0.
    assert np.median(smooth) <= 0.05, smooth
    # Rough: median 14.6%, worst 42% on that measure (docs/fidelity.md: the
    # EEVEE column is not re-rendered for the docs yet).
    assert np.median(rough) <= 0.16, rough
    assert max(smooth + rough) <= 0.45, smooth + rough
    for row in randomised:
        assert row["eevee"] <= 1.6 * row["eevee_fit"] + 0.02, (row["label"], row["eevee"], row["eevee_fit"])
