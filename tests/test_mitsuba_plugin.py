"""The Mitsuba 3 plugin ``germer_paint`` against the models (not against
Mitsuba): ``bsdf.eval`` at random geometries vs ``lut.Paint.mueller`` in the
same Stokes bases, and a rendered oracle (a plane, a directional emitter, an
orthographic sensor, the ``stokes`` integrator, a ``polarizer`` in front of
the emitter for polarized light) vs the model's Stokes vectors.

Runs in the Mitsuba environment (``.venv-mitsuba``, made by
``scripts/bootstrap.sh``; ``scripts/test.sh`` runs this file there) and is
skipped where mitsuba is not installed.  The variant is the first polarized
one that renders here (``choose_variant``)."""

from __future__ import annotations

import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from lut import Paint, bench  # noqa: E402
from lut.polarized import mitsuba_bsdf, mueller_lut  # noqa: E402
from lut.polarized.scenes import direction, germer_dict, model_mueller, model_stokes, plane_oracle  # noqa: E402

VARIANT, WHY = mitsuba_bsdf.choose_variant()
#: The randomised acceptance set's first eight paints (two smooth, six rough
#: of both distributions, g of both signs), their colours made grey (the
#: green channel's) so one wavelength compares with one channel.
PAINTS = [
    (label, Paint(**{**p.to_dict(), "rho": p.rho[1], "single": p.single[1]}))
    for label, p in bench.random_paints(24)[:8]
]


@pytest.fixture(scope="module", autouse=True)
def variant():
    mi.set_variant(VARIANT)
    mitsuba_bsdf.register()
    return VARIANT


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return str(tmp_path_factory.mktemp("mueller"))


def plugin(paint: Paint, cache: str, **extra):
    return mi.load_dict({**germer_dict(paint, cache), **extra})


def model(paint, tl, pl, tv, pv):
    """The model's Mueller matrix x cos θl in Mitsuba's Stokes bases of the
    shading frame (grey paints: one channel is every channel)."""
    return model_mueller(paint, tl, pl, tv, pv, channel=0)


def vector(v):
    return mi.Vector3f(*(float(x) for x in v))


def first(x) -> float:
    """The first value of a scalar or a JIT array (the tests work in any variant)."""
    return float(np.ravel(np.array(x))[0])


def shading_point(view, wavelength=550.0):
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.wi = vector(view)
    si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
    si.wavelengths = mi.UnpolarizedSpectrum(float(wavelength))
    return si


def matrix(m) -> np.ndarray:
    return np.array([[first(m[i][j]) for j in range(4)] for i in range(4)])


def evaluate(bsdf, light, view, wavelength=550.0, ctx=None):
    """eval's Mueller matrix (first wavelength) of light from ``light`` seen from ``view``."""
    return matrix(bsdf.eval(ctx or mi.BSDFContext(), shading_point(view, wavelength), vector(light)))


def evaluate_many(bsdf, lights, views, ctx=None):
    """eval's Mueller matrices (n, 4, 4) at n geometries: one call over arrays
    in a JIT variant, one per geometry in a scalar one."""
    ctx = ctx or mi.BSDFContext()
    if not dr.is_jit_v(mi.Float):
        return np.array([evaluate(bsdf, light, view, ctx=ctx) for light, view in zip(lights, views, strict=True)])
    si = dr.zeros(mi.SurfaceInteraction3f, len(views))
    si.wi = mi.Vector3f(*(mi.Float(np.ascontiguousarray(c, dtype=np.float32)) for c in np.asarray(views).T))
    si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
    si.wavelengths = mi.UnpolarizedSpectrum(550.0)
    wo = mi.Vector3f(*(mi.Float(np.ascontiguousarray(c, dtype=np.float32)) for c in np.asarray(lights).T))
    m = bsdf.eval(ctx, si, wo)
    return np.stack([np.stack([np.array(m[i][j])[0] for j in range(4)], -1) for i in range(4)], -2)


def is_delta(bs) -> bool:
    return bool(int(first(bs.sampled_type)) & int(mi.BSDFFlags.DeltaReflection))


#: The eval test's paints: both smooth ones and the rough ones the rendered
#: test bakes anyway (Gaussian with g < 0 and a large slope with g > 0, an
#: exponential with g > 0).  A rough paint's Mueller LUT takes about two
#: minutes to bake on two cores, so the other three rough paints of
#: ``PAINTS`` are not baked in every CI run (the three kept cover both
#: distributions and both signs of g).
EVAL = [0, 1, 2, 4, 5]


@pytest.mark.parametrize("index", EVAL, ids=[PAINTS[i][0] for i in EVAL])
def test_eval_matches_the_models_mueller_matrix(index, cache):
    """200 random geometries: up to 75° (the fidelity measure's domain), the
    normal included, and 48 with light or view between 75° and 89° (towards
    a silhouette).  M00's RMS error relative to M00's RMS within 1% and
    every element of Mij/M00 within 0.01 at every geometry (the design's
    acceptance figures).  The plugin evaluates the facet term in
    closed form and looks single scattering and the diffuse term up in the
    Mueller LUT with Dr.Jit, equal to the numpy lookup
    (``MuellerLUT.mueller(..., closed_facet=True)``) to float32 rounding."""
    _, paint = PAINTS[index]
    bsdf = plugin(paint, cache)
    rng = np.random.default_rng(7 + index)
    n = 200
    tl, tv = np.arccos(rng.uniform(np.cos(np.radians(75.0)), 1.0, (2, n)))
    tl[:3], tv[3:6] = 0.0, 0.0  # light or view along the normal
    tl[6:30], tv[30:54] = np.radians(rng.uniform(75.0, 89.0, (2, 24)))  # grazing, towards a silhouette
    pl, pv = rng.uniform(-np.pi, np.pi, (2, n))
    ref = model(paint, tl, pl, tv, pv)
    got = evaluate_many(bsdf, direction(tl, pl).T, direction(tv, pv).T)
    rms = np.sqrt(np.mean((got[:, 0, 0] - ref[:, 0, 0]) ** 2) / np.mean(ref[:, 0, 0] ** 2))
    assert rms < 0.01, f"M00 RMS error {rms:.2%}"
    normalised = np.abs(got / got[:, :1, :1] - ref / ref[:, :1, :1]).max(axis=(1, 2))
    assert normalised.max() < 0.01, f"largest error of Mij/M00 {normalised.max():.4f}"
    table = mueller_lut.load_mueller_lut(mueller_lut.bake_mueller(paint, cache))
    lookup = table.mueller(tl, tv, pv - pl + np.pi, paint, frame=pl - np.pi, closed_facet=True)
    lookup = lookup[:, 0] * np.cos(tl)[:, None, None]
    assert np.abs(got - lookup).max() < 1e-4 * np.abs(lookup[:, 0, 0]).max()  # float32 angles in JIT variants


def test_a_coloured_paint_is_weighted_per_wavelength_as_the_paper_weights_rho(cache):
    """A spectrum of ρ: at each wavelength the plugin is the grey paint of
    that wavelength's ρ (Eq. 27's k(ρ) per wavelength, not per RGB)."""
    _, paint = PAINTS[1]
    spectrum = [(400.0, 0.05), (550.0, 0.3), (700.0, 0.85)]
    bsdf = plugin(paint, cache, rho={"type": "spectrum", "value": spectrum})
    light, view = direction(0.5, 0.2), direction(0.8, 2.5)
    for wavelength, rho in spectrum:
        grey = plugin(Paint(**{**paint.to_dict(), "rho": rho}), cache)
        np.testing.assert_allclose(evaluate(bsdf, light, view, wavelength), evaluate(grey, light, view), rtol=1e-4)
    assert not np.allclose(evaluate(bsdf, light, view, 400.0), evaluate(bsdf, light, view, 700.0), rtol=0.05)


def expected_stokes(paint, tl, pl, tv, pv, polarizer=None):
    """The model's Stokes vector at the plane oracle's sensor, in its basis."""
    return model_stokes(paint, tl, pl, tv, pv, polarizer, channel=0)


GEOMETRIES = [(0.5, 0.3, 0.7, 2.0), (1.2, -1.0, 0.3, 0.5), (0.2, 0.0, 1.1, 3.0), (1.25, 2.0, 1.25, -1.1)]


@pytest.mark.parametrize("index", [0, 1, 2, 5], ids=[PAINTS[i][0] for i in (0, 1, 2, 5)])
def test_rendered_stokes_vectors_match_the_model(index, cache):
    """S0..S3 rendered vs the model's within 1% of the unpolarized S0, for
    unpolarized light and through a polarizer at three angles (measured
    worst 0.61% and 0.35%, docs/polarized.md).  The renderer's white (its
    own Lambertian under the same emitter and sensor, whose RGB of a flat
    spectrum is not exactly 1) is divided out; the stratified sampler gives
    both renders the same wavelengths."""
    _, paint = PAINTS[index]
    bsdf = plugin(paint, cache)
    white = {"type": "diffuse", "reflectance": {"type": "rgb", "value": 1.0}}
    for tl, pl, tv, pv in GEOMETRIES:
        light, view = direction(tl, pl), direction(tv, pv)
        scale = plane_oracle(white, light, view)[0] / (np.cos(tl) / np.pi)
        assert abs(scale - 1.0) < 0.01  # the set-up itself: unit irradiance, a linear sensor
        unpolarized = expected_stokes(paint, tl, pl, tv, pv)
        for polarizer in (None, 0.0, 45.0, 110.0):
            got = plane_oracle(bsdf, light, view, polarizer) / scale
            ref = expected_stokes(paint, tl, pl, tv, pv, polarizer)
            err = np.abs(got - ref).max() / unpolarized[0]
            assert err < 0.01, f"{(tl, pl, tv, pv)}, polarizer {polarizer}: {got} vs {ref}"


def test_sampling_is_consistent_with_eval_and_pdf(cache):
    """Each non-delta sample's weight is eval/pdf, and the pdf integrates to
    the non-delta share of the mixture (1 for a rough paint)."""
    rng = np.random.default_rng(3)
    for index in (0, 1):  # smooth, rough
        _, paint = PAINTS[index]
        bsdf = plugin(paint, cache)
        ctx = mi.BSDFContext()
        si = shading_point(direction(0.6, 0.4))
        for _ in range(20):
            u = rng.random(3)
            bs, weight = bsdf.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
            if is_delta(bs):
                continue
            value = first(bsdf.eval(ctx, si, bs.wo)[0][0])
            assert np.isclose(first(weight[0][0]), value / first(bs.pdf), rtol=1e-4)
        # the pdf over the hemisphere (a midpoint rule in cos θ and φ)
        mu = (np.arange(64) + 0.5) / 64
        phi = (np.arange(64) + 0.5) / 64 * 2 * np.pi
        pdfs = [first(bsdf.pdf(ctx, si, vector(direction(np.arccos(m), f)))) for m in mu for f in phi]
        total = sum(pdfs) * (2 * np.pi / 64 / 64)
        fresnel = first(mi.fresnel(float(np.cos(0.6)), float(paint.n))[0])
        mirror = 0.0 if paint.slope else float(np.clip(fresnel * paint.facet, 0.05, 0.95))
        assert abs(total - (1.0 - mirror)) < 0.03, (index, total, mirror)


def test_the_smooth_mirror_is_fresnel_times_facet(cache):
    """A smooth paint's delta sample carries facet x the Fresnel reflection
    Mueller matrix, in Mitsuba's Stokes bases: the whole matrix equals
    Mitsuba's own smooth ``conductor`` of the same index and no absorption
    (an independent build of the same matrix and bases), times facet."""
    _, paint = PAINTS[0]
    bsdf = plugin(paint, cache)
    conductor = mi.load_dict({"type": "conductor", "eta": float(paint.n), "k": 0.0})
    for theta, phi in ((0.9, 0.0), (0.3, 2.0), (1.3, -1.0)):
        si = shading_point(direction(theta, phi))
        bs, weight = bsdf.sample(mi.BSDFContext(), si, 0.0, mi.Point2f(0.5, 0.5))
        assert is_delta(bs)
        np.testing.assert_allclose(np.array(bs.wo).ravel(), direction(theta, phi + np.pi), atol=1e-6)
        reference, reference_weight = conductor.sample(mi.BSDFContext(), si, 0.0, mi.Point2f(0.5, 0.5))
        got = matrix(weight) * first(bs.pdf) / paint.facet
        np.testing.assert_allclose(got, matrix(reference_weight), atol=1e-5)
        assert abs(got[0, 0] - first(mi.fresnel(float(np.cos(theta)), float(paint.n))[0])) < 1e-5


def test_importance_transport_is_the_same_light_path(cache):
    """In importance transport the roles of wi and wo swap: the light arrives
    along -si.wi.  eval's matrix over cos θ of ``wo`` is then the radiance
    mode's with the directions exchanged (as Mitsuba's pplastic)."""
    _, paint = PAINTS[1]
    bsdf = plugin(paint, cache)
    importance = mi.BSDFContext(mi.TransportMode.Importance)
    for (tl, pl), (tv, pv) in (((0.4, 0.2), (0.9, 2.6)), ((1.1, -2.0), (0.2, 0.7))):
        light, view = direction(tl, pl), direction(tv, pv)
        radiance = evaluate(bsdf, light, view) / light[2]
        adjoint = evaluate(bsdf, view, light, ctx=importance) / view[2]
        np.testing.assert_allclose(adjoint, radiance, rtol=1e-5, atol=1e-8)


@pytest.mark.parametrize(
    ("props", "message"),
    [
        ({"n": 0.5}, r"germer_paint property n must be a real number in \[1, 4\], got 0.5"),
        ({"slope": -1.0}, r"germer_paint property slope must be 0 \(smooth\) or a real number in \[0.001, 3\]"),
        ({"g": 1.5}, r"germer_paint property g must be"),
        ({"facet": -0.5}, r"germer_paint property facet must be"),
        ({"distribution": "cauchy"}, r"germer_paint property distribution must be one of 'gaussian', 'exponential'"),
        ({"rho": 1.5}, r"germer_paint property rho must be .*\[0, 1\]"),
        ({"single": -0.1}, r"germer_paint property single must be .*\[0, 1\]"),
        ({"cache": 5.0}, r"germer_paint property cache must be a directory path"),
    ],
)
def test_bad_properties_are_refused_by_name(props, message, cache):
    with pytest.raises(Exception, match=message):
        mi.load_dict({"type": "germer_paint", "cache": cache, **props})


def test_a_variant_that_is_not_polarized_is_refused_with_the_choices():
    mi.set_variant("scalar_rgb")
    try:
        with pytest.raises(ValueError, match="polarized"):
            mitsuba_bsdf.register()
    finally:
        mi.set_variant(VARIANT)


def test_the_polarized_command_writes_stokes_images_and_a_figure(tmp_path, capsys):
    """``python -m lut polarized``: a preset's sphere with germer_paint and
    pplastic (the smooth preset, whose Mueller LUT bakes in seconds); the
    EXRs hold S0..S3 (RGB each), whose luminance is light's (S0 >= |(S1, S2,
    S3)|), and the figure is written."""
    import OpenImageIO as oiio

    from lut.__main__ import main

    assert main(["polarized", "--preset", "glossy_white", "--out", str(tmp_path), "--size", "16", "--spp", "2"]) == 0
    out = capsys.readouterr().out
    assert "germer_paint: rendered" in out and "pplastic: rendered" in out
    assert (tmp_path / "glossy_white-polarized.png").stat().st_size > 10_000
    for what in ("dolp", "aolp"):
        assert (tmp_path / f"glossy_white-{what}-germer_paint.png").stat().st_size > 100
    for kind in ("germer_paint", "pplastic"):
        image = oiio.ImageInput.open(str(tmp_path / f"glossy_white-stokes-{kind}.exr"))
        assert image.spec().channelnames[:4] == ("S0.R", "S0.G", "S0.B", "S1.R")
        pixels = image.read_image("float").reshape(16, 16, 4, 3)
        image.close()
        # Luminance: CIE ȳ weighs every wavelength positively (an sRGB
        # channel does not), so the Stokes vectors of Y are those of real light.
        y = pixels @ np.array([0.2126, 0.7152, 0.0722])
        assert y[:, :, 0].max() > 0.0
        assert np.all(np.sqrt((y[:, :, 1:] ** 2).sum(axis=2)) <= y[:, :, 0] * (1 + 1e-3) + 1e-6)
