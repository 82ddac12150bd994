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
    # Rough: median 14.6%, worst 42% on that measure (docs/fidelity.md has
    # the whole randomised set's figures).
    assert np.median(rough) <= 0.16, rough
    assert max(smooth + rough) <= 0.45, smooth + rough
    for row in randomised:
        assert row["eevee"] <= 1.6 * row["eevee_fit"] + 0.02, (row["label"], row["eevee"], row["eevee_fit"])


@pytest.fixture(scope="module")
def converged(randomised, tmp_path_factory):
    """The same spheres in the scene's EEVEE mode Converged, rendered at the
    viewport's samples (``eevee.VIEWPORT_SAMPLES``: a final render's 64 are
    4x slower here, and the bins average many pixels besides)."""
    from lut.render import eevee
    from scripts import eevee_fidelity

    paints = [(row["label"], row["paint"]) for row in randomised]
    return eevee_fidelity.measure(
        paints, tmp_path_factory.mktemp("luts"), eevee_mode="CONVERGED", samples=eevee.VIEWPORT_SAMPLES
    )


@pytest.mark.render
def test_eevee_converged_renders_of_the_randomised_set_are_as_reported(randomised, converged):
    """The scene's EEVEE mode Converged on the randomised set's spheres:
    where a type keeps its exact fit, it renders as the exact mode does;
    where it takes a converged fit, its render is no worse than the exact
    fit's and not far from what it reports (within 1.6 times it plus 2%, as
    the exact fits).  The spheres' bins reach views of about 65° (pixels
    next to the silhouette are left out), so the converged fits' gain, at a
    sharp lobe's grazing mirror, is checked on the plane oracle below."""
    taken = 0
    for exact, conv in zip(randomised, converged, strict=True):
        assert exact["label"] == conv["label"]
        if conv["eevee_fit"] == pytest.approx(exact["eevee_fit"], rel=1e-9):
            assert conv["eevee"] == pytest.approx(exact["eevee"], abs=0.01), conv["label"]
            continue
        taken += 1
        assert conv["eevee_fit"] < exact["eevee_fit"], conv["label"]
        assert conv["eevee"] <= exact["eevee"] + 0.02, (conv["label"], conv["eevee"], exact["eevee"])
        assert conv["eevee"] <= 1.6 * conv["eevee_fit"] + 0.02, (conv["label"], conv["eevee"], conv["eevee_fit"])
    assert taken >= 2


@pytest.mark.render
def test_a_converged_eevee_render_comes_near_its_prediction_on_the_plane_oracle(addon_registered, tmp_path):
    """A sharp exponential paint of the randomised set (slope 0.12, the
    brightest grazing mirror of its set), both EEVEE modes, on the plane
    oracle over its EEVEE grid (``addon.scenes.GRID_EEVEE``, θv to 75°: the
    geometry that dominates the measure is the mirror at θl = θv = 75°), the
    mean of 32 × 32 pixels at one sample (closures picked per pixel at
    random, so the mean is a many-sample render's).  Measured on Blender
    5.0 (16 × 16 pixels): the exact fit renders at 30.2% (predicts 30.7%),
    the converged one at 10.7% (predicts 10.0%; the mean of the grazing
    mirror's pixels is noisy)."""
    import bpy

    from addon import nodes, scenes
    from lut.lutfiles import baking
    from lut.render import bake as render_bake
    from lut.render import eevee, fitting

    label, paint = bench.random_paints(12)[2]
    assert paint.slope > 0 and paint.distribution == "exponential"
    calibration = eevee.calibration_for(bpy.app.version)
    table = baking.load_lut(baking.bake(paint, tmp_path))
    amps = table.amplitudes(paint)
    oracle = scenes.Oracle(engine=scenes.EEVEE)
    oracle.scene.render.resolution_x = oracle.scene.render.resolution_y = 32
    oracle.scene.eevee.taa_render_samples = 1
    tl, tv, ph = scenes.grid_points(paint, scenes.GRID_EEVEE)
    model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
    rendered, predicted = {}, {}
    for mode in ("EXACT", "CONVERGED"):
        fit = fitting.fit_lut(table, "EEVEE", calibration=calibration, eevee_mode=mode)
        path = tmp_path / f"weights-{mode}.exr"
        fitting.write_fit(fit, path)
        material = oracle.material(f"{label}-{mode}")
        nodes.wire(
            material, {"EEVEE": nodes.build_group(fit, path)}, render_bake.node_inputs(paint, fit.internal_reflectance)
        )
        got = np.array([oracle.radiance(*g) / oracle.irradiance for g in zip(tl, tv, ph, strict=True)])
        rendered[mode] = measure.relative_rms(got, model)
        predicted[mode] = measure.relative_rms(fit.radiance(amps, tl, tv, ph), model)
        assert not fit.sums_exactly if mode == "CONVERGED" else fit.sums_exactly
    assert rendered["EXACT"] <= 1.3 * predicted["EXACT"] + 0.02, (rendered, predicted)
    assert rendered["CONVERGED"] <= 1.6 * predicted["CONVERGED"] + 0.02, (rendered, predicted)
    assert rendered["CONVERGED"] < 0.6 * rendered["EXACT"], rendered


@pytest.mark.render
def test_a_converged_fits_noise_at_the_viewports_samples_is_as_the_noise_model_predicts(addon_registered, tmp_path):
    """The per-pixel spread of a converged fit on the plane oracle (a flat
    lit plane: every pixel the same geometry, so its spread is the noise),
    at the geometry where the noise model (``eevee.spread``) predicts the
    most: at one sample and at the viewport's 16, near the prediction and
    not above it by more than 15% (the fit counts that spread against its
    goals, so a model that under-predicted would let noise through), and
    falling with samples at least as fast as the model's N^-0.7.  Measured on
    Blender 5.0 at this paint's noisiest geometry (16 × 16 pixels): 72%
    (predicted 66%) at one sample, 8.4% (9.5%) at 16."""
    import bpy

    from addon import nodes, scenes
    from lut.lutfiles import baking
    from lut.render import bake as render_bake
    from lut.render import eevee, fitting

    label, paint = bench.random_paints(12)[2]
    calibration = eevee.calibration_for(bpy.app.version)
    table = baking.load_lut(baking.bake(paint, tmp_path))
    amps = table.amplitudes(paint)
    fit = fitting.fit_lut(table, "EEVEE", calibration=calibration, eevee_mode="CONVERGED")
    assert not fit.sums_exactly, label
    path = tmp_path / "weights.exr"
    fitting.write_fit(fit, path)
    oracle = scenes.Oracle(engine=scenes.EEVEE)
    oracle.scene.render.resolution_x = oracle.scene.render.resolution_y = 32
    material = oracle.material(label)
    nodes.wire(
        material, {"EEVEE": nodes.build_group(fit, path)}, render_bake.node_inputs(paint, fit.internal_reflectance)
    )
    tl, tv, ph = scenes.grid_points(paint, scenes.GRID_EEVEE)
    per_point = [eevee.spread(fit, amps, 1, ([a], [b], [c])) for a, b, c in zip(tl, tv, ph, strict=True)]
    g = int(np.argmax(per_point))
    point = ([tl[g]], [tv[g]], [ph[g]])
    measured, predicted = {}, {}
    for samples in (1, eevee.VIEWPORT_SAMPLES):
        oracle.scene.eevee.taa_render_samples = samples
        image = oracle.image(tl[g], tv[g], ph[g]).reshape(-1, 3)
        measured[samples] = np.sqrt(image.var(axis=0).sum() / (image.mean(axis=0) ** 2).sum())
        predicted[samples] = eevee.spread(fit, amps, samples, point)
    for samples in measured:
        assert 0.5 * predicted[samples] <= measured[samples] <= 1.15 * predicted[samples], (measured, predicted)
    assert measured[eevee.VIEWPORT_SAMPLES] <= measured[1] * eevee.VIEWPORT_SAMPLES**-eevee.CONVERGENCE, measured
