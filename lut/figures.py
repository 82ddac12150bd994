"""The paper's Figs. 1-3 from the models, as PNG plots (matplotlib).

Fig. 1: the transmission facet model at θi = 60°, n = 1.5: the BTDF in the
plane of incidence, normalized to its peak, for several Gaussian RMS slopes σ,
and the sine of the BTDF-weighted mean refraction angle against sin θi.
Figs. 2 and 3: f_r, η and P against θs in the plane of incidence at
θi = 60°, for 45° incident light, for the three presets' model terms (the
paper's model curves; the measurements are not reproduced).  The paper's
single wavelengths are used: 632.8 nm for the white and CARC paints,
441.6 nm for the red one.
"""

from __future__ import annotations

import pathlib

import numpy as np

from . import models
from .lutfiles.files import atomic_target
from .paint import presets

THETA_I = np.radians(60.0)
SIGMAS = (0.05, 0.1, 0.2, 0.3, 0.5, 1.0)
#: Finer than the default quadrature, so plotted curves show no kinks.
FIGURE_NODES = (8, 12)


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path):
    """Write a figure atomically (``lut.lutfiles.files.atomic_target``)."""
    with atomic_target(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path


def in_plane(theta_s_deg):
    """Model angles of a signed in-plane scan (negative: the source's side)."""
    theta_s_deg = np.asarray(theta_s_deg, dtype=float)
    return np.radians(np.abs(theta_s_deg)), np.where(theta_s_deg < 0, np.pi, 0.0)


def mean_refraction_sine(theta_i, sigma, n=1.5, nodes=160):
    """sin of the BTDF-weighted mean refraction angle (Fig. 1 right)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    tt, wt = 0.25 * np.pi * (x + 1.0), 0.25 * np.pi * w
    pt = (np.arange(96) + 0.5) * 2 * np.pi / 96 - np.pi
    t, p = np.meshgrid(tt, pt, indexing="ij")
    f = models.facet_transmission(theta_i, t, p, n=n, slope=sigma, mueller=False)
    dw = np.sin(t) * wt[:, None]
    return np.sin(np.sum(t * f * dw) / np.sum(f * dw))


def figure1(path):
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    tt = np.linspace(0.0, 89.5, 600)
    for sigma in SIGMAS:
        f = models.facet_transmission(THETA_I, np.radians(tt), 0.0, n=1.5, slope=sigma, mueller=False)
        left.plot(tt, f / f.max(), label=f"σ = {sigma}")
    left.axvline(np.degrees(np.arcsin(np.sin(THETA_I) / 1.5)), color="0.6", ls=":", lw=1)
    left.set(xlabel="θt [deg]", ylabel="BTDF / peak", title="Fig. 1 (left): θi = 60°, n = 1.5")
    left.legend(fontsize=8)
    sin_i = np.linspace(0.05, 0.95, 10)
    for sigma in SIGMAS:
        right.plot(sin_i, [mean_refraction_sine(np.arcsin(s), sigma) for s in sin_i], marker=".", label=f"σ = {sigma}")
    right.plot(sin_i, sin_i / 1.5, color="0.5", ls="--", label="Snell, n = 1.5")
    right.set(xlabel="sin θi", ylabel="sin <θt>", title="Fig. 1 (right): mean refraction angle")
    right.legend(fontsize=8)
    fig.tight_layout()
    out = _save(fig, path)
    plt.close(fig)
    return out


def _terms(name):
    """The model terms of a preset at the paper's wavelength, as functions of
    (θs, φs) returning Mueller BRDFs, with their labels."""
    p = presets.preset(name)
    kw = {"n": p.n}
    if name == "glossy_white":
        rho = float(p.rho.at(632.8))
        return {
            "subsurface diffuse": lambda ts, ps: models.smooth_diffuse(THETA_I, ts, ps, rho=rho, **kw),
            "facet (slope 0.05)": lambda ts, ps: models.facet_reflection(THETA_I, ts, ps, slope=0.05, **kw),
        }
    rough = {"slope": p.slope, "distribution": p.distribution, **kw}
    if name == "glossy_red":
        # The paper's combination model: facet plus single volume scattering
        # (the preset adds a diffuse term for rendering; Fig. 2 has none).
        single = float(p.single.at(441.6))

        def combination(ts, ps):
            return models.facet_reflection(THETA_I, ts, ps, **rough) + single * models.rough_single(
                THETA_I, ts, ps, g=p.g, nodes=FIGURE_NODES, **rough
            )

        return {
            "facet": lambda ts, ps: models.facet_reflection(THETA_I, ts, ps, **rough),
            "single volume": lambda ts, ps: single * models.smooth_single(THETA_I, ts, ps, g=p.g, **kw),
            "combination": combination,
        }
    single, rho = float(p.single.at(632.8)), float(p.rho.at(632.8))

    def monte_carlo(ts, ps):
        return (
            models.facet_reflection(THETA_I, ts, ps, **rough)
            + single * models.rough_single(THETA_I, ts, ps, g=p.g, nodes=FIGURE_NODES, **rough)
            + models.rough_diffuse(THETA_I, ts, ps, rho=rho, **rough)
        )

    return {
        "facet": lambda ts, ps: models.facet_reflection(THETA_I, ts, ps, **rough),
        "rough interface model (Sec. 2.5)": monte_carlo,
    }


def figure_paint(name, path, title):
    plt = _pyplot()
    ts_deg = np.linspace(-85.0, 85.0, 171)
    ts, ps = in_plane(ts_deg)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for label, fn in _terms(name).items():
        q = models.polarization_parameters(fn(ts, ps))
        faint = q["fr"] < 1e-6 * np.max(q["fr"])  # underflowed lobe tails: no defined polarization
        q = {k: np.where(faint, np.nan, v) for k, v in q.items()}
        axes[0].semilogy(ts_deg, q["fr"], label=label)
        axes[1].plot(ts_deg, np.degrees(q["eta"]), label=label)
        axes[2].plot(ts_deg, q["p"], label=label)
    axes[0].set(xlabel="θs [deg]", ylabel="f_r [1/sr]")
    axes[1].set(xlabel="θs [deg]", ylabel="η [deg]", ylim=(-95, 95))
    axes[2].set(xlabel="θs [deg]", ylabel="P", ylim=(0, 1.05))
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    out = _save(fig, path)
    plt.close(fig)
    return out


def all_figures(directory):
    """Write fig1.png, fig2_white.png, fig2_red.png, fig3_carc.png; return the paths."""
    directory = pathlib.Path(directory)
    return [
        figure1(directory / "fig1.png"),
        figure_paint("glossy_white", directory / "fig2_white.png", "Fig. 2 (left): glossy white, θi = 60°, 632.8 nm"),
        figure_paint("glossy_red", directory / "fig2_red.png", "Fig. 2 (right): glossy red, θi = 60°, 441.6 nm"),
        figure_paint("green_carc", directory / "fig3_carc.png", "Fig. 3: green CARC, θi = 60°, 632.8 nm"),
    ]
