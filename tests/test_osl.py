"""Cycles' OSL variant (``lut.render.fitting.fit_osl``): the ramp closures'
formulas, the signed fit's bound, its gain on paints nobody tuned for, and
its weights file.  Numpy only; the renders are in test_osl_render.py."""

import dataclasses

import numpy as np
import pytest

from lut import bench
from lut.render import bake as render_bake
from lut.render import closures, fitting, measure

#: A randomised set the fit was not tuned on (seeds other than the
#: benchmarks'): rough and smooth paints over the panel's ranges, and dark
#: facet-dominated ones.
SET = bench.random_paints(8, seed=31) + bench.dark_paints(3, seed=32)


@pytest.fixture(scope="module")
def bakes(tmp_path_factory):
    directory = tmp_path_factory.mktemp("osl")
    return {label: (paint, render_bake.bake_for_render(paint, directory, targets=("CYCLES",), osl=True))
            for label, paint in SET}  # fmt: skip


def test_ramp_knots_are_the_ramps_of_cycles_osl():
    """The knots' hats share every position (they sum to 1), so a ramp of
    equal knots is Cycles' plain lobe: diffuse_ramp of white knots is 1/π
    (no cos θl: the ramp is the whole light dependence), phong_ramp's is the
    normalised Phong lobe (e + 2)/(2π)·(R·l)^e·cos θl."""
    x = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(sum(closures.ramp_hat(x, j) for j in range(closures.RAMP_KNOTS)), 1.0, atol=1e-12)
    assert closures.ramp_hat(3 / 7, 3) == pytest.approx(1.0) and closures.ramp_hat(3.5 / 7, 3) == pytest.approx(0.5)
    tl, tv, ph = np.array([0.3, 1.2, 0.7]), np.array([0.4, 0.2, 1.1]), np.array([0.0, 2.0, 0.5])
    diffuse = sum(c.evaluate(tl, tv, ph) for c in closures.ramp_closures(()))
    np.testing.assert_allclose(diffuse, 1.0 / np.pi)
    e = 8.0
    phong = sum(c.evaluate(tl, tv, ph) for c in closures.ramp_closures((e,)) if c.kind == "phong_ramp")
    r_dot_l = np.sin(tv) * np.cos(ph) * np.sin(tl) + np.cos(tv) * np.cos(tl)
    expected = np.where(r_dot_l > 0, (e + 2) / (2 * np.pi) * np.maximum(r_dot_l, 0) ** e * np.cos(tl), 0.0)
    np.testing.assert_allclose(phong, expected, atol=1e-12)
    # The diffuse ramp about the view: equal knots give Cycles' bump
    # shadowing term over π where l·v > 0 (the retro Toon's factor), else 0.
    retro = sum(c.evaluate(tl, tv, ph) for c in closures.ramp_closures((), retro=True) if c.kind == "retro_ramp")
    l_dot_v = -np.sin(tl) * np.sin(tv) * np.cos(ph) + np.cos(tl) * np.cos(tv)
    tan2_v, tan2_l = np.tan(tv) ** 2, np.tan(tl) ** 2  # G1 of GGX at θl with α² = tan²θv/8 (tv, tl < 70°)
    shadow = 2.0 / (1.0 + np.sqrt(1.0 + tan2_v / 8.0 * tan2_l))
    np.testing.assert_allclose(retro, np.where(l_dot_v > 0, shadow / np.pi, 0.0))
    assert (l_dot_v > 0).any() and (l_dot_v < 0).any() and np.all(shadow < 1.0)
    # One knot alone: its hat at the ramp's position (cos θl = 2/7 is knot 2's peak).
    knot = closures.Closure("diffuse_ramp", knot=2)
    assert knot.evaluate(np.arccos(2 / 7), 0.3, 0.0) == pytest.approx(1 / np.pi)
    assert knot.evaluate(np.arccos(4 / 7), 0.3, 0.0) == pytest.approx(0.0)


def test_the_variant_keeps_the_svm_closures_and_never_renders_negative(bakes):
    """The variant's SVM closures and weights are the SVM fit's (a scene
    without OSL renders exactly the SVM fit), and for each component alone
    and for random colours of each type its radiance is nowhere negative:
    lights to 89.99° (a diffuse ramp keeps its first knot at the horizon,
    where the SVM closures fade), views to 89° between the texture's
    columns, every azimuth, on a grid off the one the bound is fitted on;
    each point against the SVM radiance at that same point (the
    bound's margin, ``fitting.OSL_MARGIN``, covers the points between)."""
    rng = np.random.default_rng(5)
    tl, tv, ph = (a.ravel() for a in np.meshgrid(
        np.radians(np.r_[np.arange(0.0, 89.0, 1.7), 88.6, 89.3, 89.9, 89.99]),
        np.radians(np.r_[np.arange(0.0, 89.0, 2.9), 89.0]),
        np.radians(np.arange(0.0, 181.0, 7.0)), indexing="ij"))  # fmt: skip
    for label, (_paint, result) in bakes.items():
        svm, variant = result.fits["CYCLES"], result.osl
        k = len(svm.closures)
        assert variant.closures[:k] == svm.closures
        np.testing.assert_allclose(variant.weights[:k], svm.weights, atol=1e-5 * np.abs(svm.weights).max())
        assert variant.osl and all(c.osl for c in variant.closures[k:])
        colours = [np.eye(3)[:, [c] * 3].T for c in range(3)] + [rng.uniform(0.0, 1.0, (3, 3)) for _ in range(3)]
        for amps in colours:
            radiance = variant.radiance(amps, tl, tv, ph)
            local = svm.radiance(amps, tl, tv, ph)
            floor = -1e-3 * local - 1e-9 * local.max()  # rounding where both underflow
            worst = np.argmin(radiance - floor)
            assert np.all(radiance >= floor), (label, radiance.flat[worst], local.flat[worst])


def test_the_ramps_lower_the_measure_on_paints_nobody_tuned_for(bakes):
    """The variant keeps its ramps only where they bring the type nearer its
    goals (``fitting.shortfall``: its worst component's error over its goal,
    whole and grazing band), so its shortfall is never above the SVM fit's;
    for each paint's own colour it is at most 0.2% (absolute) worse on
    either figure, and on most rough paints of the set it is nearer the
    paint: the median of the whole figure falls by a tenth at least."""
    gains = []
    for label, (paint, result) in bakes.items():
        svm_fit, osl_fit = result.fits["CYCLES"], result.osl
        goals = measure.goals("OSL", paint.slope == 0)

        def short(fit, goals=goals):
            return fitting.shortfall(
                (fit.residual, fit.reference), (fit.grazing_residual, fit.grazing_reference), goals
            )

        assert short(osl_fit) <= short(svm_fit) + 1e-9, (label, short(svm_fit), short(osl_fit))
        errors = result.all_errors(paint)
        svm, osl = errors["CYCLES"], errors[render_bake.OSL_VARIANT]
        assert all(o <= s + 0.002 for o, s in zip(osl, svm, strict=True)), (label, svm, osl)
        if paint.slope > 0:
            gains.append(osl[0] / svm[0])
    assert np.median(gains) < 0.9, gains


def test_the_variants_file_packs_three_knots_a_texel_and_reads_back(bakes, tmp_path):
    """A ramp's eight knots take three texels per component (R, G, B), the
    file reads back the weights it was written with, and a bake finds it
    cached; the SVM rows take a texel per three rows, in both files."""
    paint, result = next(iter(bakes.values()))
    variant = result.osl
    layout = fitting.texels(variant.closures, variant.rows)
    packed = [slots for slots in layout if variant.closures[next(s for s in slots if s)[0]].osl]
    ramp_rows = [r for r in variant.rows if variant.closures[r[0]].osl]
    families = {(variant.closures[k].kind, variant.closures[k].exponent) for k, _ in ramp_rows}
    assert ramp_rows and sum(slot is not None for slots in packed for slot in slots) == len(ramp_rows)
    assert all(len({c for _, c in filter(None, slots)}) == 1 for slots in packed)  # one component a texel
    assert len(packed) <= 3 * len(fitting.COMPONENTS) * len(families)
    assert len(layout) == -(-(len(variant.rows) - len(ramp_rows)) // 3) + len(packed)
    back = fitting.read_fit(result.osl_path)
    np.testing.assert_allclose(back.weights, variant.weights, atol=1e-5 * np.abs(variant.weights).max())
    assert back.closures == variant.closures and back.osl
    assert result.osl_path.name.startswith("paintfit-cyclesosl-")
    again = render_bake.bake_for_render(paint, result.lut_path.parent, targets=("CYCLES",), osl=True)
    assert again.computed == []
    svm = result.fits["CYCLES"]
    flat = [slot for slots in fitting.texels(svm.closures, svm.rows) for slot in slots if slot is not None]
    assert flat == [tuple(r) for r in svm.rows]


def test_the_variant_needs_cycles_and_an_svm_base(bakes):
    paint, result = next(iter(bakes.values()))
    with pytest.raises(ValueError, match="osl=True needs 'CYCLES'"):
        render_bake.bake_for_render(paint, result.lut_path.parent, targets=("EEVEE",), osl=True)
    with pytest.raises(ValueError, match="base must be an SVM Cycles fit"):
        fitting.fit_osl(result.lut, result.osl)
    with pytest.raises(ValueError, match="exponents must lie in"):
        fitting.fit_osl(result.lut, result.fits["CYCLES"], exponents=(-1.0,))
    with pytest.raises(ValueError, match="target 'CYCLES' only"):
        fitting.fit_path(result.lut_path, "EEVEE", osl=True)


def test_the_variants_radiance_is_what_its_reported_error_measures(bakes):
    """``Fit.radiance`` of the variant (the SVM closures and the ramps, with
    the weights its texture gives) against the model on the measure's grid
    gives the figures the variant reports, whole and over the grazing band,
    within 0.2% (the fit measures against the model at its LUT's quadrature
    sizes, ``Paint.brdf`` at its own defaults)."""
    for label, (paint, result) in bakes.items():
        amps = result.lut.amplitudes(paint)
        tl, tv, ph = measure.points(paint.slope == 0)
        model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
        measured = measure.errors(result.osl.radiance(amps, tl, tv, ph), model, tl)
        reported = result.all_errors(paint)[render_bake.OSL_VARIANT]
        for got, promised in zip(measured, reported, strict=True):
            assert abs(got - promised) <= 0.002, (label, measured, reported)


def test_a_cached_variant_is_made_again_when_its_svm_fit_changed(tmp_path):
    """A variant's file names the SVM fit it was made from (its content key,
    the same for a fit and its file read back): a Cycles fit written anew
    under the same name (another release's fit, a file restored from
    elsewhere) makes the next bake fit the variant again, from that fit."""
    _label, paint = SET[1]
    first = render_bake.bake_for_render(paint, tmp_path, targets=("CYCLES",), osl=True)
    svm = first.fits["CYCLES"]
    assert (
        first.osl.base_key
        == fitting.content_key(svm)
        == fitting.content_key(fitting.read_fit(first.fit_paths["CYCLES"]))
    )
    other = dataclasses.replace(svm, weights=svm.weights * 0.9)  # a valid fit of the same LUT, other weights
    fitting.write_fit(other, first.fit_paths["CYCLES"])
    again = render_bake.bake_for_render(paint, tmp_path, targets=("CYCLES",), osl=True)
    assert again.computed == [render_bake.OSL_VARIANT]
    assert again.osl.base_key == fitting.content_key(other) != first.osl.base_key
    k = len(other.closures)
    np.testing.assert_allclose(again.osl.weights[:k], other.weights, atol=1e-5 * np.abs(other.weights).max())
    loaded = render_bake.load_baked(again.lut_path, targets=("CYCLES",), osl=True)
    assert loaded.computed == [] and loaded.osl.base_key == again.osl.base_key
