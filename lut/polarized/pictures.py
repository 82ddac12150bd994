"""Polarized pictures of a paint: a sphere under a sun and a sky rendered by
Mitsuba 3 (``lut.polarized.scenes.sphere_scene``) with ``germer_paint`` and,
beside it, Mitsuba's ``pplastic`` given the same paint; written as the
Stokes images (an EXR of S0..S3, RGB each) and one figure per paint: S0
(sRGB), the degree of linear polarization and its angle of luminance Y
(``scenes.luminance``), the angle on a colour wheel (hue the angle,
brightness the degree).  Spectral polarized variants.  Needs mitsuba (``.venv-mitsuba``);
``python -m lut polarized`` is its command."""

from __future__ import annotations

import pathlib
import time

import numpy as np

from ..lutfiles.files import atomic_target
from ..paint.core import Paint
from . import scenes


def render(paint: Paint, *, size=128, spp=16, cache=None, pplastic=True, variant=None) -> dict:
    """{"germer_paint": stokes, "pplastic": stokes} (``scenes.stokes_images``,
    (4, H, W, 3)) and "seconds" (render time of each, the Mueller LUT's bake
    excluded) and "variant" of the sphere scene, rendered in ``variant``
    (default: ``mitsuba_bsdf.choose_variant``)."""
    import mitsuba as mi

    from . import mitsuba_bsdf

    if variant is None:
        variant = mitsuba_bsdf.choose_variant()[0]
    mi.set_variant(variant)
    mitsuba_bsdf.register()
    bsdfs = {"germer_paint": scenes.germer_dict(paint, cache)}
    if pplastic:
        bsdfs["pplastic"] = scenes.pplastic_dict(paint)
    out = {"seconds": {}, "variant": variant}
    for name, bsdf in bsdfs.items():
        scene = mi.load_dict(scenes.sphere_scene(bsdf, size=size, spp=spp))  # bakes or reads the LUT
        start = time.perf_counter()
        image = np.array(mi.render(scene))
        out["seconds"][name] = time.perf_counter() - start
        out[name] = scenes.stokes_images(image)
    return out


def _srgb(linear):
    linear = np.clip(linear, 0.0, None)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055).clip(0.0, 1.0)


def angle_colours(dolp, aolp):
    """RGB of the angle of linear polarization as a hue (period π) with the
    degree as brightness (saturated at ``DOLP_FULL``)."""
    import matplotlib.colors

    hue = (aolp % np.pi) / np.pi
    value = np.clip(dolp / DOLP_FULL, 0.0, 1.0)
    return matplotlib.colors.hsv_to_rgb(np.stack((hue, np.ones_like(hue), value), axis=-1))


#: The degree of linear polarization shown at full brightness in the angle's picture.
DOLP_FULL = 0.5


def write(directory, name: str, rendered: dict, title: str) -> list[pathlib.Path]:
    """Write per BSDF ``<name>-stokes-<bsdf>.exr`` (S0..S3, RGB each) and the
    degree and angle of linear polarization of luminance as pictures
    (``<name>-dolp-<bsdf>.png``, magma over [0, 1]; ``<name>-aolp-<bsdf>.png``,
    hue the angle, brightness the degree), and ``<name>-polarized.png`` (rows:
    the BSDFs; columns: S0, degree, angle, and a colour wheel), each
    atomically.  Returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import OpenImageIO as oiio

    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    kinds = [k for k in ("germer_paint", "pplastic") if k in rendered]
    paths = []
    polarization = {k: scenes.degree_and_angle(scenes.luminance(rendered[k])) for k in kinds}
    for kind in kinds:
        stokes = rendered[kind]
        pixels = np.ascontiguousarray(np.moveaxis(stokes, 0, 2).reshape(stokes.shape[1:3] + (12,)), np.float32)
        path = directory / f"{name}-stokes-{kind}.exr"
        spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 12, "float")
        spec.channelnames = tuple(f"S{i}.{c}" for i in range(4) for c in "RGB")
        with atomic_target(path) as tmp:
            out = oiio.ImageOutput.create(tmp)
            if out is None or not out.open(tmp, spec) or not out.write_image(pixels) or not out.close():
                raise OSError(f"cannot write {path}: {oiio.geterror()}")
        paths.append(path)
        dolp, aolp = polarization[kind]
        for what, picture in (("dolp", plt.get_cmap("magma")(dolp)[..., :3]), ("aolp", angle_colours(dolp, aolp))):
            path = directory / f"{name}-{what}-{kind}.png"
            with atomic_target(path) as tmp:
                plt.imsave(tmp, np.clip(picture, 0.0, 1.0), format="png")
            paths.append(path)
    fig, axes = plt.subplots(len(kinds), 4, figsize=(11, 2.9 * len(kinds)), squeeze=False)
    scale = max(float(np.percentile(rendered[k][0], 99.5)) for k in kinds) or 1.0
    for row, kind in zip(axes, kinds, strict=True):
        stokes = rendered[kind]
        dolp, aolp = polarization[kind]
        seconds = rendered.get("seconds", {}).get(kind)
        label = kind + (f" ({seconds:.1f} s)" if seconds is not None else "")
        row[0].imshow(_srgb(stokes[0] / scale))
        row[0].set_title(f"{label}: S0", fontsize=9)
        shown = row[1].imshow(dolp, cmap="magma", vmin=0.0, vmax=1.0)
        row[1].set_title("degree of linear polarization (Y)", fontsize=9)
        fig.colorbar(shown, ax=row[1], fraction=0.046)
        row[2].imshow(angle_colours(dolp, aolp))
        row[2].set_title(f"angle (brightness: degree, full at {DOLP_FULL:g})", fontsize=9)
        _wheel(row[3])
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path = directory / f"{name}-polarized.png"
    with atomic_target(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    paths.append(path)
    return paths


def _wheel(ax, size=101):
    """The colour wheel of the angle's picture: hue the angle (0° along +x,
    counter-clockwise, period 180°), brightness the degree (radius)."""
    y, x = np.mgrid[-1 : 1 : size * 1j, -1 : 1 : size * 1j]
    radius = np.hypot(x, y)
    colours = angle_colours(np.clip(radius, 0.0, 1.0) * DOLP_FULL, np.arctan2(-y, x))
    colours[radius > 1.0] = 1.0
    ax.imshow(colours)
    ax.set_title("angle of polarization (0° → right)", fontsize=9)
