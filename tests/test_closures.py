"""lut.render.closures, lut.render.nnls and lut.render.fitting: closure kinds, non-negative least
squares, and the fit of a paint type's LUT (numpy side)."""

import dataclasses
import functools

import numpy as np
import pytest

import lut
from lut import bench
from lut.lutfiles import baking
from lut.lutfiles import format as lutfile
from lut.render import bake as render_bake
from lut.render import closures, fitting, measure
from lut.render.nnls import nnls, nnls_gram_batch


def test_nnls_matches_scipy():
    optimize = pytest.importorskip("scipy.optimize")
    rng = np.random.default_rng(2)
    for _ in range(20):
        a, b = rng.random((50, 10)), rng.random(50) - 0.4
        x = nnls(a, b)
        assert np.all(x >= 0)
        np.testing.assert_allclose(x, optimize.nnls(a, b)[0], atol=1e-9)


def test_batched_nnls_reaches_scipys_optimum_on_near_collinear_problems():
    """The batched active set solves each problem to the optimum (objective
    equal to scipy's) even with nearly collinear columns, as Toon ramps are."""
    optimize = pytest.importorskip("scipy.optimize")
    rng = np.random.default_rng(3)
    a = rng.random((40, 6))
    a[:, 5] = 0.999 * a[:, 4] + 0.001 * rng.random(40)
    b = rng.random((30, 40)) - 0.3
    x = nnls_gram_batch(np.repeat((a.T @ a)[None], 30, axis=0), b @ a)
    assert np.all(x >= 0)
    for i in range(30):
        best = optimize.nnls(a, b[i])[0]
        assert np.sum((a @ x[i] - b[i]) ** 2) <= np.sum((a @ best - b[i]) ** 2) * (1 + 1e-9) + 1e-15
    capped = nnls_gram_batch(np.repeat((a.T @ a)[None], 30, axis=0), b @ a * 50, upper=np.ones(6))
    assert np.all(capped <= 1.0) and np.all(capped >= 0)


def test_warm_started_nnls_reaches_the_same_optimum():
    """A warm start (forward selection's previous weights, padded with the
    new closure at zero; or any positive guess, wrong support included)
    reaches the optimum of the cold start: the KKT conditions hold (x >= 0,
    no gradient on the positive weights, none pointing into the zero ones)."""
    rng = np.random.default_rng(5)
    a = rng.random((40, 7))
    a[:, 6] = 0.995 * a[:, 5] + 0.005 * rng.random(40)  # near collinear, as Toon ramps are
    b = rng.random((30, 40)) - 0.35
    gram = np.repeat((a.T @ a)[None], 30, axis=0)
    rhs = b @ a
    cold = nnls_gram_batch(gram, rhs)
    fewer = nnls_gram_batch(gram[:, :6, :6], rhs[:, :6])
    starts = {
        "selection": np.pad(fewer, ((0, 0), (0, 1))),
        "guess": rng.random((30, 7)),
        "wrong support": np.where(cold > 0, 0.0, 1.0),
    }
    for name, start in starts.items():
        x = nnls_gram_batch(gram, rhs, start=start)
        w = rhs - np.einsum("bij,bj->bi", gram, x)
        assert np.all(x >= 0), name
        assert np.abs(w[x > 0]).max() < 1e-8, name
        assert w[x == 0].max(initial=-1.0) < 1e-8, name
        np.testing.assert_allclose(x, cold, atol=1e-7, err_msg=name)
    assert (cold == 0).any() and (cold > 0).any()  # both kinds of constraint are met above


def test_toon_closures_integrate_to_their_cone():
    """A Toon closure with no smoothing is a uniform cone: its hemispherical
    integral of the contribution (cos included) over directions is 1."""
    closure = closures.Closure("diffuse_toon", 0.5, 0.0)
    theta = np.linspace(0, np.pi / 2, 200_001)
    value = closure.evaluate(theta, 0.3, 0.0)
    y = value * np.sin(theta)
    integral = np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(theta)) * 2 * np.pi  # trapezoid rule
    assert integral == pytest.approx(1.0, rel=1e-3)


def test_metallic_closure_without_shadowing_is_the_facet_term():
    closure = closures.Closure("metallic", ior=1.5, roughness=0.5)
    theta_l, theta_v, phi = np.radians([20.0, 40.0]), np.radians([30.0, 35.0]), np.array([0.2, 1.0])
    facet = lut.models.facet_reflection(theta_l, theta_v, phi, n=1.5, slope=0.25, mueller=False) * np.cos(theta_l)
    value = closure.evaluate(theta_l, theta_v, phi)
    assert np.all(value <= facet) and np.all(value > 0.99 * facet)  # G is just below 1 here


def test_glossy_is_the_metallic_lobe_without_fresnel():
    rng = np.random.default_rng(5)
    tl, tv, ph = rng.uniform(0, 1.3, 50), rng.uniform(0, 1.3, 50), rng.uniform(-np.pi, np.pi, 50)
    glossy = closures.Closure("glossy", roughness=0.6).evaluate(tl, tv, ph)
    metallic = closures.Closure("metallic", ior=1.5, roughness=0.6).evaluate(tl, tv, ph)
    _, cos_d = closures._half_vector(tl, tv, ph)
    rs, rp = lut.models.fresnel.reflection_coefficients(cos_d, 1.5)
    np.testing.assert_allclose(metallic, glossy * 0.5 * (rs**2 + rp**2), rtol=1e-9, atol=1e-14)


def test_retro_toon_peaks_toward_the_light_and_oren_nayar_brightens_backward():
    """The two closures that back-scattering pigments need: the retro Toon is
    largest with the viewer at the light; Oren-Nayar is brighter toward the
    light's side than away from it."""
    retro = closures.Closure("retro_toon", 0.3, 0.2)
    at_light, away = retro.evaluate(0.5, 0.5, np.pi), retro.evaluate(0.5, 0.5, 0.0)
    assert at_light > 0.2 and away == 0.0
    oren = closures.Closure("oren_nayar", roughness=1.0)
    assert oren.evaluate(0.8, 0.8, np.pi) > 1.3 * oren.evaluate(0.8, 0.8, 0.0)


def test_every_kind_is_finite_at_normal_incidence_and_grazing():
    theta = np.array([0.0, 1e-9, np.radians(89.9), np.pi / 2])
    tl, tv, ph = np.meshgrid(theta, theta, [0.0, 1.0, np.pi], indexing="ij")
    for kind in closures.CLOSURE_KINDS:
        value = closures.Closure(kind, 0.3, 0.3, 1.5, 0.5).evaluate(tl, tv, ph)
        assert np.all(np.isfinite(value)) and np.all(value >= 0), kind


def test_unknown_kind_and_target_are_refused():
    with pytest.raises(ValueError, match="closure kind must be one of"):
        closures.Closure("velvet")
    with pytest.raises(ValueError, match="target must be one of CYCLES, EEVEE"):
        closures.candidates({"n": 1.5, "g": 0, "slope": 0.2, "distribution": "gaussian"}, "WORKBENCH")


def test_candidates_per_target():
    satin = {"n": 1.4, "g": 0.0, "slope": 0.25, "distribution": "gaussian"}
    cycles = closures.candidates(satin)
    assert closures.Closure("metallic", ior=1.4, roughness=0.5) in cycles  # the paper's facet term exactly
    assert {c.kind for c in closures.candidates(satin, "EEVEE")} <= {"lambert", "metallic", "glossy"}
    assert {c.kind for c in closures.candidates(satin, exact_metallic=False) if c.grey} == {"ggx"}
    smooth = {"n": 1.5, "g": 0.0, "slope": 0.0, "distribution": "gaussian"}
    assert not any(c.grey for c in closures.candidates(smooth))  # a smooth facet term is the mirror
    # EEVEE: a smooth type's mirror leaves one reflection closure free, for a retro lobe.
    assert {c.kind for c in closures.candidates(smooth, "EEVEE")} == {"lambert", "retro_glossy"}
    assert "retro_glossy" not in {c.kind for c in closures.candidates(smooth)}


def test_eevee_fits_keep_to_two_reflection_closures_with_the_mirror(tmp_path):
    """EEVEE sums two reflection closures exactly: a smooth type's mirror is
    one, so its exact fit takes at most one more (a retro lobe, for a
    back-scattering pigment); a rough type's exact fit at most two lobes."""
    from lut.render import eevee

    smooth = baking.load_lut(baking.bake(lut.Paint(rho=0.03, single=0.2, g=-0.5), tmp_path))
    rough = baking.load_lut(baking.bake(lut.Paint(rho=0.03, single=0.2, g=-0.5, slope=0.2), tmp_path))
    smooth_fit = fitting.fit_lut(smooth, "EEVEE", calibration=(5, 0), eevee_mode="EXACT")
    assert smooth_fit.mirror
    assert [c.kind for c in smooth_fit.closures if eevee.is_reflection(c)] == ["retro_glossy"]
    rough_fit = fitting.fit_lut(rough, "EEVEE", calibration=(5, 0), eevee_mode="EXACT")
    assert 1 <= sum(eevee.is_reflection(c) for c in rough_fit.closures) <= eevee.EXACT_REFLECTION_CLOSURES
    assert "retro_glossy" not in {c.kind for c in rough_fit.closures}


def test_retro_glossy_is_a_ggx_lobe_about_the_view():
    """Its value depends on the light-view angle alone (the lobe's frame is
    the view direction), peaks with the light at the viewer, and is the GGX
    lobe seen head-on there."""
    lobe = closures.Closure("retro_glossy", roughness=0.6)
    tl = np.radians([10.0, 40.0, 70.0])
    at_viewer = lobe.evaluate(tl, tl, np.pi)  # light and view together
    head_on, _ = closures.ggx_lobe(0.0, 0.0, 0.0, 0.6)
    np.testing.assert_allclose(at_viewer, head_on, rtol=1e-9)
    # The same light-view angle (40°) from different geometries, the same value.
    a = lobe.evaluate(np.radians(20.0), np.radians(20.0), 0.0)  # mirror geometry, γ = 40°
    b = lobe.evaluate(np.radians(40.0), 0.0, 0.0)  # view along the normal, γ = 40°
    assert a == pytest.approx(b, rel=1e-9) and a < 0.5 * head_on
    assert lobe.evaluate(np.radians(95.0), 0.2, 0.0) == 0.0


@pytest.fixture(scope="module")
def luts(tmp_path_factory):
    directory = tmp_path_factory.mktemp("fit")
    return {
        "smooth": lut.load_lut(lut.bake(lut.Paint(), directory)),
        "dark satin": lut.load_lut(lut.bake(lut.Paint(rho=0.04, slope=0.45), directory)),
        "dark matte": lut.load_lut(lut.bake(lut.Paint(rho=0.05, slope=2.0, distribution="exponential"), directory)),
    }


def _nodes(table):
    """The quadrature sizes a LUT was baked with (Paint.brdf's options)."""
    return {k: tuple(table.meta[k]) for k in ("single_nodes", "diffuse_nodes") if k in table.meta}


def _rendered(fitted, tl, tv, ph, amps, evaluate=None):
    """Radiance f·cos θl the node group renders at (θl, θv, φ) (N, 3): the
    closures with the weights of the texture's nearest column, computed
    here without ``lut.render.fitting``'s helpers."""
    j = np.rint(np.cos(tv) * (len(fitted.cos_view) - 1)).astype(int)  # the nearest column
    got = np.zeros((tl.size, 3))
    for k, closure in enumerate(fitted.closures):
        value = closure.evaluate(tl, tv, ph) if evaluate is None else evaluate(closure, tl, tv, ph)
        got += value[:, None] * (fitted.weights[k][:, j, 0].T @ amps.T)
    return got


def _direct_errors(fitted, table, paint, evaluate=None):
    """(whole, grazing band) fidelity measure computed directly: what the
    node group renders against the paper's model, ``Paint.brdf`` · cos θl,
    at ``measure.points`` (the mirror's neighbourhood left out for a smooth
    paint), every geometry counted once."""
    tl, tv, ph = measure.points(paint.slope == 0)
    model = paint.brdf(tl, tv, ph, **_nodes(table)) * np.cos(tl)[:, None]
    got = _rendered(fitted, tl, tv, ph, table.amplitudes(paint), evaluate)
    band = tl >= np.radians(60.0) - 1e-9
    rms = [np.sqrt(np.sum((got[s] - model[s]) ** 2) / np.sum(model[s] ** 2)) for s in (slice(None), band)]
    return float(rms[0]), float(rms[1])


@pytest.mark.parametrize("name", ["dark satin", "smooth"])
def test_fit_errors_are_the_measure_of_what_the_node_group_renders(luts, name):
    """Fit.error and Fit.grazing_error (from the Gram matrices) are the
    fidelity measure computed directly, whole and over the grazing band:
    the closures with the weights texture's nearest column against the
    paper's model, at the measure's geometries, for any colour."""
    fitted = fitting.fit_lut(luts[name], "CYCLES")
    slope = luts[name].meta["type"]["slope"]
    paint = lut.Paint(rho=(0.6, 0.1, 0.02), single=(0.0, 0.2, 0.1), g=0.0, slope=slope, facet=0.8)
    if name == "smooth":
        paint = lut.Paint()
    amps = luts[name].amplitudes(paint)
    whole, grazing = _direct_errors(fitted, luts[name], paint)
    assert fitted.error(amps) == pytest.approx(whole, rel=1e-6)
    assert fitted.grazing_error(amps) == pytest.approx(grazing, rel=1e-6)
    assert fitting.reported_errors(fitted.grams(), amps) == pytest.approx((whole, grazing), rel=1e-6)
    assert fitting.gram_error(fitted.residual, fitted.reference, amps) == pytest.approx(whole, rel=1e-6)


def test_eevee_fit_reports_the_measure_of_its_calibrated_closures(tmp_path):
    """A sharp Gaussian facet term of the randomised set (slope 0.078), fitted
    for EEVEE against Blender 5.0's measured closures: its reported errors
    are the measure of those closures as EEVEE draws them (computed
    directly), and a weights file read back reports the same."""
    from lut.render import eevee

    paint = dict(bench.random_paints())["#23 gau 0.0779 g +0.43"]
    table = baking.load_lut(baking.bake(paint, tmp_path))
    fitted = fitting.fit_lut(table, "EEVEE", calibration=(5, 0))
    amps = table.amplitudes(paint)
    evaluate = functools.partial(eevee.evaluate, version=(5, 0))
    whole, grazing = _direct_errors(fitted, table, paint, evaluate)
    assert fitted.error(amps) == pytest.approx(whole, rel=1e-6)
    assert fitted.grazing_error(amps) == pytest.approx(grazing, rel=1e-6)
    back = fitting.read_fit(fitting.write_fit(fitted, tmp_path / "w.exr"))
    assert back.error(amps) == pytest.approx(fitted.error(amps), rel=1e-9)
    assert back.grazing_error(amps) == pytest.approx(fitted.grazing_error(amps), rel=1e-9)


def test_nearest_column_of_the_weights_texture_renders_the_reported_error(luts):
    """The node group reads the weights texture by its nearest column
    (Closest interpolation, which EEVEE samples without mipmaps): that
    lookup, against the LUT the fit was made from, renders the error the
    fit reports against the paper's model (to the LUT's own accuracy), and
    every ``VIEW_SUBDIVISION``-th column is a fitted view with the columns
    between on the straight line between its neighbours."""
    fitted = fitting.fit_lut(luts["dark satin"], "CYCLES")
    assert len(fitted.cos_view) == fitting.TEXTURE_VIEWS
    paint = lut.Paint(rho=(0.6, 0.1, 0.02), single=(0.0, 0.2, 0.1), g=0.0, slope=0.45, facet=0.8)
    tl, tv, ph = measure.points(False)
    ref = luts["dark satin"].evaluate(tl, tv, ph, paint) * np.cos(tl)[:, None]
    amps = luts["dark satin"].amplitudes(paint)
    got = _rendered(fitted, tl, tv, ph, amps)
    assert measure.relative_rms(got, ref) == pytest.approx(fitted.error(amps), abs=0.002)
    # The node group's lookup coordinate puts the texel of that column under every cos θv.
    scale, offset = fitting.texture_u(len(fitted.cos_view))
    cos = np.linspace(0.0, 1.0, 100_001)
    texel = np.minimum(np.floor((scale * cos + offset) * len(fitted.cos_view)), len(fitted.cos_view) - 1)
    np.testing.assert_array_equal(texel, np.rint(cos * (len(fitted.cos_view) - 1)))
    views = fitted.weights[:, :, :: fitting.VIEW_SUBDIVISION]
    assert views.shape[2] == fitting.VIEWS
    between = fitting.resample_views(views, fitting.view_cosines(), fitted.cos_view)
    np.testing.assert_allclose(fitted.weights, between, rtol=1e-12, atol=1e-15)


def test_facet_dominated_dark_paints_keep_facet_closures(luts):
    """Dark paints are mostly facet reflection: forward selection keeps the
    closures that fit it (energy ranking once dropped them all)."""
    for name in ("dark satin", "dark matte"):
        fitted = fitting.fit_lut(luts[name], "CYCLES")
        assert any(c.kind in ("metallic", "glossy", "sheen") for c in fitted.closures)
        assert fitted.component_errors()["facet"] < 0.11  # 10.4% on the fidelity measure, grazing light in full
        black = lut.Paint(
            rho=0.0, slope=luts[name].meta["type"]["slope"], distribution=luts[name].meta["type"]["distribution"]
        )
        assert fitted.error(luts[name].amplitudes(black)) < 0.11  # 10.4%: the facet term alone


def test_fits_respect_the_budget_and_the_mix_factor_bound(luts):
    for name, table in luts.items():
        for target in closures.TARGETS:
            fitted = fitting.fit_lut(table, target, eevee_mode="EXACT")
            assert sum(c.cost for c in fitted.closures) <= fitting.BUDGET[target] + fitting.EXTRA_BUDGET[target]
            lean = fitting.fit_lut(table, target, extra_budget=0, eevee_mode="EXACT")
            assert sum(c.cost for c in lean.closures) <= fitting.BUDGET[target]
            if target == "EEVEE":  # a converged fit within its own budget
                wide = fitting.fit_lut(table, target, eevee_mode="CONVERGED")
                assert sum(c.cost for c in wide.closures) <= fitting.CONVERGED_BUDGET + fitting.CONVERGED_EXTRA
                assert np.all(wide.weights >= 0)
            assert np.all(fitted.weights >= 0)
            for k, c in enumerate(fitted.closures):
                assert fitted.weights[k].max() <= c.max_weight + 1e-12
                if c.grey:  # a grey lobe serves the (grey) facet component only
                    assert fitted.weights[k, 1:].max() == 0
            assert fitted.mirror == (name == "smooth")


def test_closures_beyond_the_budget_only_while_the_target_is_missed(tmp_path):
    """A moderately rough exponential type of the randomised set (slope 0.94):
    within the budget its facet component misses the Cycles target (and its
    paint renders 5.5% off in the Cycles oracle); the extra closures bring
    the component and the paint down.  A type the budget fits well takes
    none."""
    paint = dict(bench.random_paints())["#11 exp 0.9432 g +0.33"]
    table = baking.load_lut(baking.bake(paint, tmp_path))
    amps = table.amplitudes(paint)
    lean = fitting.fit_lut(table, "CYCLES", extra_budget=0)
    full = fitting.fit_lut(table, "CYCLES")
    target = fitting.TARGET_ERROR["CYCLES"]["rough"]
    assert lean.component_errors()["facet"] > target
    # On the fidelity measure the extra closures barely help this facet term
    # (docs/render.md: Smith shadowing under grazing light); they are kept
    # only where they bring the fit nearer its goals.
    goals = measure.goals("CYCLES", False)
    near = fitting.shortfall((full.residual, full.reference), (full.grazing_residual, full.grazing_reference), goals)
    lean_near = fitting.shortfall(
        (lean.residual, lean.reference), (lean.grazing_residual, lean.grazing_reference), goals
    )
    assert near <= lean_near
    if sum(c.cost for c in full.closures) > fitting.BUDGET["CYCLES"]:
        assert near < lean_near
    assert full.error(amps) < lean.error(amps) + 0.002
    easy = lut.Paint(rho=0.5, slope=0.3)
    easy_table = baking.load_lut(baking.bake(easy, tmp_path))
    assert sum(c.cost for c in fitting.fit_lut(easy_table, "CYCLES").closures) <= fitting.BUDGET["CYCLES"]


def test_weights_file_round_trip_and_tampering(luts, tmp_path):
    fitted = fitting.fit_lut(luts["dark satin"], "CYCLES")
    path = fitting.write_fit(fitted, tmp_path / "w.exr")
    back = fitting.read_fit(path)
    assert back.closures == fitted.closures and back.rows == fitted.rows
    np.testing.assert_allclose(back.weights, fitted.weights, rtol=1e-6, atol=1e-9)  # float32 texels
    assert back.error(np.ones((3, 3))) == pytest.approx(fitted.error(np.ones((3, 3))))
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x10
    path.write_bytes(bytes(data))
    with pytest.raises(lutfile.LUTError):
        fitting.read_fit(path)


def test_weights_texture_packs_three_rows_a_texel_and_a_channel_each_when_dispersive(luts, tmp_path):
    """A fit with one weight per view puts three weight rows in each texel
    (R, G, B: a node group reads them with one lookup); one with a weight
    per channel (a dispersive type) keeps a texel per row, channel t holding
    tile t.  Both read back exactly."""
    fitted = fitting.fit_lut(luts["dark satin"], "CYCLES")
    layout = fitting.texels(fitted.closures, fitted.rows)
    assert len(fitted.rows) > 3 and len(layout) == -(-len(fitted.rows) // 3)
    assert [slot for slots in layout for slot in slots if slot] == fitted.rows
    scale = np.array([0.5, 1.0, 2.0])  # a different weight per channel
    dispersive = dataclasses.replace(fitted, weights=fitted.weights * scale)
    assert fitting.texels(dispersive.closures, dispersive.rows, 3) == [(row,) * 3 for row in fitted.rows]
    for fit in (fitted, dispersive):
        back = fitting.read_fit(fitting.write_fit(fit, tmp_path / f"w{fit.weights.shape[3]}.exr"))
        np.testing.assert_allclose(back.weights, fit.weights, rtol=1e-6, atol=1e-9)


def test_randomised_types_fit_within_their_targets():
    """The closure fits of a randomised set of paints (fixed seed; dark and
    light, smooth to slope 3, both distributions, g of both signs), at the
    paints' own colours, on the fidelity measure against the paper's model,
    whole and over the grazing band, each against its goal
    (``measure.goals``): the median within the goal, every smooth paint and
    every rough one of slope below 1.5 within both goals, and the very rough
    ones, whose facet terms no Cycles lobe is broad enough to draw (Cycles
    clamps microfacet roughness to α <= 1 and shadows every lobe:
    docs/render.md), within twice them."""
    import tempfile

    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for _, paint in bench.random_paints(12, seed=7):
            result = render_bake.bake_for_render(paint, directory, targets=("CYCLES",))
            rows.append((paint, result.all_errors(paint)["CYCLES"]))
    for smooth in (True, False):
        chosen = [(p, e) for p, e in rows if (p.slope == 0) == smooth]
        for which, goal in enumerate(measure.goals("CYCLES", smooth)):
            figures = [e[which] for _, e in chosen]
            assert np.median(figures) < goal, (smooth, which, figures)
            for paint, errors in chosen:
                allowed = goal if paint.slope < 1.5 else 2.0 * goal
                assert errors[which] < allowed, (paint, which, errors)


def test_the_batched_spd_solver_is_numpys_solve():
    """``nnls.solve_spd`` (a batched Cholesky factor and substitution over
    the batch, no LAPACK solve per matrix) agrees with numpy's solve on random positive definite systems,
    regularised near-singular ones and 1x1 ones."""
    from lut.render.nnls import solve_spd

    rng = np.random.default_rng(11)
    m = rng.normal(size=(40, 6, 9, 5))  # rank 5 in 9 unknowns: singular without the ridge
    a = m @ np.swapaxes(m, -1, -2) + 1e-10 * np.eye(9)
    b = np.einsum("...ij,...j->...i", a, rng.normal(size=(40, 6, 9)))
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", a, solve_spd(a, b)), b, atol=1e-8 * np.abs(b).max())
    m = rng.normal(size=(30, 7, 7))
    a = m @ np.swapaxes(m, -1, -2) + 0.1 * np.eye(7)
    b = rng.normal(size=(30, 7))
    np.testing.assert_allclose(solve_spd(a, b), np.linalg.solve(a, b[..., None])[..., 0], rtol=1e-10, atol=1e-12)
    assert solve_spd(np.array([[4.0]]), np.array([2.0])) == pytest.approx([0.5])
    # A matrix of the batch that is not positive definite (its Cholesky
    # factor does not exist) sends the whole batch to elimination.
    a[3] = [[1.0 if i == j else (2.0 if abs(i - j) == 1 else 0.0) for j in range(7)] for i in range(7)]
    np.testing.assert_allclose(solve_spd(a, b), np.linalg.solve(a, b[..., None])[..., 0], rtol=1e-9, atol=1e-11)
    # Either way a right-hand side with more batch axes than its matrices broadcasts.
    many = rng.normal(size=(2, 30, 7))
    for mats in (a, np.abs(a[:1]) + 7.0 * np.eye(7)):  # elimination, and Cholesky
        want = np.linalg.solve(np.broadcast_to(mats, (2, 30, 7, 7)), many[..., None])[..., 0]
        np.testing.assert_allclose(solve_spd(mats, many), want, rtol=1e-9, atol=1e-11)


@pytest.mark.parametrize("target", ["CYCLES", "EEVEE"])
def test_a_fits_radiance_is_what_its_reported_error_measures(tmp_path, target):
    """``Fit.radiance`` (what the node group renders, by the target's closure
    responses) against the model on the measure's grid gives the error the
    fit reports, whole and over the grazing band, for a colour the fit was
    not made at.  The reported error is that of full-float closure colours
    (a quadratic form in the colour); EEVEE's G-buffer truncation of them
    (``eevee.stored_colour``) moves this paint's measure by under 1.5%
    (measured: 0.66%, grazing 1.01%)."""
    paint = lut.Paint(n=1.55, rho=(0.6, 0.3, 0.05), single=0.1, g=0.3, slope=0.3, distribution="exponential")
    table = baking.load_lut(baking.bake(paint, tmp_path))
    fit = fitting.fit_lut(table, target, calibration=(5, 0) if target == "EEVEE" else None)
    amps = table.amplitudes(paint)
    tl, tv, ph = measure.points(smooth=False)
    model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
    whole, grazing = measure.errors(fit.radiance(amps, tl, tv, ph, rounding="none"), model, tl)
    if target == "EEVEE":
        stored = measure.errors(fit.radiance(amps, tl, tv, ph), model, tl)
        assert abs(stored[0] - whole) < 0.015 and abs(stored[1] - grazing) < 0.015, (stored, whole, grazing)
    assert whole == pytest.approx(fit.error(amps), rel=0.03, abs=0.002)
    assert grazing == pytest.approx(fit.grazing_error(amps), rel=0.03, abs=0.002)
    assert fit.radiance(amps, tl[:5], tv[:5], ph[:5]).shape == (5, 3)


def test_mirror_rows_are_the_measures_mirror_points_of_its_views():
    """The mirror point of each view (θl = θv, φ = 0) is one geometry of the
    measure's grid for every view the grid holds, weighted as one lattice
    cell; views past the measure's 75° get no weight."""
    theta_v = np.radians([5.0, 40.0, 75.0, 80.0, 89.5])
    theta_l, phi, weight = fitting.mirror_rows(theta_v)
    assert theta_l.shape == phi.shape == weight.shape == (5, 1)
    np.testing.assert_allclose(theta_l[:, 0], theta_v)
    assert np.all(measure.mirror_distance(theta_l, theta_v[:, None], phi) < 1e-6)  # arccos near 1: about 1e-8
    cell = np.radians(5.0) * np.radians(10.0)
    np.testing.assert_allclose(weight[:, 0], [np.sqrt(cell)] * 3 + [0.0, 0.0])
    tl, tv, ph = measure.points(False)
    on_grid = measure.mirror_distance(tl, tv, ph) < 1e-6
    assert on_grid.sum() == measure.GRID[1].size  # the grid holds the mirror of each of its views


#: The row sets with the mirror point, tried in turn (not a default: see
#: ``fitting.DEFAULT_ROW_SETS``).
MIRROR_SETS = ("hemisphere", "mirror", "grazing", "grazing-mirror")


def test_a_sharp_exponential_peak_is_drawn_to_its_top_and_between_the_measures_points(tmp_path):
    """An exponential slope's peak is a cusp: the paper's facet term at the
    mirror direction is higher than any Beckmann lobe of the same width.
    Fitted on the mirror sets, the Cycles fit of a near-smooth exponential
    type (slope 0.08) draws the
    cusp's top within 3% at views of 30-75° (the fit without the mirror
    point drew it 7% low, and that top was 90% of the type's measure), and
    between the measure's points (``measure.BETWEEN_GRID``) it stays within
    the rough goal."""
    paint = lut.Paint(rho=(0.3, 0.1, 0.05), single=0.05, g=0.4, slope=0.08, distribution="exponential", facet=0.8)
    table = lut.load_lut(lut.bake(paint, tmp_path))
    amps = table.amplitudes(paint)
    fitted = fitting.fit_lut(table, "CYCLES", row_sets=MIRROR_SETS)
    tv = np.radians([30.0, 45.0, 60.0, 75.0])
    model = paint.brdf(tv, tv, 0.0 * tv, **_nodes(table)) * np.cos(tv)[:, None]
    ratio = fitted.radiance(amps, tv, tv, 0.0 * tv) / model  # per channel
    assert np.all(np.abs(ratio - 1.0) < 0.03), ratio
    # The control: the rows without the mirror point leave the top low.
    without = fitting.fit_lut(table, "CYCLES", row_sets=("hemisphere", "grazing"))
    low = without.radiance(amps, tv, tv, 0.0 * tv) / model
    assert np.any(np.abs(low - 1.0) > 0.03), low
    whole, band = fitting.between_errors(fitted, paint, amps)
    goals = measure.goals("CYCLES", False)
    assert whole < goals[0] and band < goals[1], (whole, band)
    assert fitted.error(amps) < goals[0], fitted.error(amps)


def _dense_binned(fitted, paint, amps, count=100_000, seed=11):
    """A fit's radiance against the model at random geometries (fixed seed),
    binned on the measure's grid as the sphere renders are
    (``bench.binned_errors``): what a curved object shows between the
    grid's points. (whole, grazing band)."""
    rng = np.random.default_rng(seed)
    tl = rng.uniform(0.0, np.radians(78.0), count)
    tv = rng.uniform(np.radians(2.0), np.radians(78.0), count)
    ph = rng.uniform(-np.pi, np.pi, count)
    model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
    whole, band, _ = bench.binned_errors(tl, tv, ph, fitted.radiance(amps, tl, tv, ph), model, smooth=False)
    return whole, band


@pytest.mark.parametrize(("label", "control"), [("#6 exp 0.0964 g -0.25", True), ("#21 exp 0.0785 g +0.41", False)])
def test_default_cycles_fits_of_sharp_cusps_hold_on_every_pixel_not_only_the_grid(tmp_path, label, control):
    """Near-smooth exponential slopes peak in a cusp at the mirror, which
    the measure's grid samples exactly at each of its views.  The default
    fit, binned over random geometries as a sphere's pixels are, is within
    the rough goals (or 1.5x what it reports, as the Cycles sphere test
    allows) and no worse than its reported figure + 0.5%.  The control:
    fitted to the grid's mirror points at their full weight (the row set
    "grazing-mirror" alone), the same paint's reported figure is beaten from
    the wrong side on #6: it reads 2.2% on the grid and 5.3% binned between
    its points."""
    paint = dict(bench.random_paints())[label]
    table = baking.load_lut(baking.bake(paint, tmp_path))
    amps = table.amplitudes(paint)
    goals = measure.goals("CYCLES", False)
    fitted = fitting.fit_lut(table, "CYCLES")
    reported = (fitted.error(amps), fitted.grazing_error(amps))
    dense = _dense_binned(fitted, paint, amps)
    for got, promised, goal in zip(dense, reported, goals, strict=True):
        assert got <= (goal if promised <= goal else 1.5 * promised), (label, dense, reported)
        assert got <= promised + 0.005, (label, dense, reported)
    if control:
        grid_fit = fitting.fit_lut(table, "CYCLES", row_sets=("grazing-mirror",))
        assert _dense_binned(grid_fit, paint, amps)[0] > grid_fit.error(amps) + 0.005


@pytest.mark.parametrize(("label", "gains"), [("#21 exp 0.0785 g +0.41", True), ("#6 exp 0.0964 g -0.25", False)])
def test_a_cusp_the_default_rows_miss_tries_its_mirror_point_and_keeps_it_only_where_it_holds_between(
    tmp_path, label, gains
):
    """Where an exponential type's facet term misses a goal on the default
    rows, the fit tries the mirror point at a quarter weight ("grazing-cusp")
    and keeps it only
    where it comes nearer the goals on the grid and between the grid's
    points alike.  #21 gains (6.3% -> 2.9% on the grid, within the goal
    between its points too); #6 keeps the default rows' fit, as the cusp
    rows' fit of #6 is worse between the grid's points (6.7% with the
    lights shifted) and on a sphere's binned pixels (7.0%)."""
    paint = dict(bench.random_paints())[label]
    table = baking.load_lut(baking.bake(paint, tmp_path))
    amps = table.amplitudes(paint)
    goals = measure.goals("CYCLES", False)
    fitted = fitting.fit_lut(table, "CYCLES")
    plain = fitting.fit_lut(table, "CYCLES", row_sets=fitting.DEFAULT_ROW_SETS["CYCLES"])
    assert plain.error(amps) > goals[0], plain.error(amps)  # the default rows miss on both
    if gains:
        assert fitted.error(amps) < goals[0] < plain.error(amps), (fitted.error(amps), plain.error(amps))
        assert fitting.between_errors(fitted, paint, amps)[0] < goals[0]
    else:
        assert fitted.closures == plain.closures
        np.testing.assert_allclose(fitted.weights, plain.weights)
        cusp = fitting.fit_lut(table, "CYCLES", row_sets=("grazing-cusp",))
        assert fitting.between_errors(cusp, paint, amps)[0] > fitting.between_errors(plain, paint, amps)[0]
