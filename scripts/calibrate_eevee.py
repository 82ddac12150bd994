"""Measure how EEVEE renders the closures a Paint LUT fit may use, and write
the tables ``lut.render.eevee`` interpolates (``lut/render/eevee_tables.py``).

Method.  A grid of spheres (one closure each, white, unit weight) under a
delta Sun (angle 0, no shadows) in a black world, seen by an orthographic
camera along +Z, rendered by EEVEE at one sample per pixel with the film
filter off, to 32-bit multilayer EXR with the Normal pass.  Every pixel is
one geometry: from its shading normal n (the pass), the view v = +Z and the
light l, (θl, θv, φ) in ``lut.models``' convention (light at azimuth π, φ = 0
the mirror direction).  One render fixes the angle γ between l and v; a
sweep of γ covers (θl, θv, |φ|).  A table on a grid of (θl, θv, |φ|) holds
the ratio of EEVEE to a reference, a smooth analytic model of what EEVEE
approximates (``lut.render.eevee.reference``): so a table cell is a slowly
varying correction, and lobes of any roughness keep their analytic shape
between cells.  The table is the least-squares fit of its trilinear
interpolation to the pixels (``lut.render.eevee.fit_table``), held near the
binned ratio Σ EEVEE / Σ reference of each cell's pixels where few pixels
reach it: binning alone is biased near a sharp lobe's mirror at grazing
angles, where a cell's pixels are weighted toward its brighter side.
Flat squares side by side (``PlaneScene``, one render per geometry) measure
the grazing band (θl, θv 50-75°, |φ| ≤ 45°) exactly, where the spheres'
pixels are those next to the silhouette; there they replace the spheres'.

Run ``python scripts/calibrate_eevee.py`` with a Python whose ``bpy`` renders
EEVEE; the tables of that Blender line (``bpy.app.version[:2]``) are added to
the file, those of other lines kept (``--only KIND ...``: only those kinds
are measured, and added to the line's other tables).  New tables change
what EEVEE fits are made from: bump ``lut.render.fitting.FIT_VERSION`` with them,
so cached fits are made again."""

from __future__ import annotations

import argparse
import math
import os
import pathlib
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut.lutfiles import files  # noqa: E402
from lut.render import eevee  # noqa: E402
from lut.render.closures import RETRO_ROUGHNESS, Closure  # noqa: E402

#: The generated module of tables.
MODULE = ROOT / "lut" / "render" / "eevee_tables.py"
#: Pixels across one sphere's cell in the render: a sphere of radius 116
#: pixels, so that with ``ERODE`` pixels left out at its silhouette the
#: pixels still reach views 79° from the normal.
CELL = 256
#: Pixels next to a sphere's silhouette left out: EEVEE shades them brighter
#: than the surface inside (Cycles does not).  Kept, as the first
#: calibrations kept them, they were every pixel of views beyond 72° (a
#: sphere of 43 pixels) and made sharp lobes' tables 8-10% too bright at
#: θv = 75°, where a rough paint's grazing mirror dominates the measure.
ERODE = 2
#: Angles γ between light and view of the sweep (degrees).
GAMMAS = tuple(range(0, 176, 5))


def calibration_closures() -> list:
    """The closures measured: every kind an EEVEE fit may use, over
    roughness and (for the Fresnel-weighted Metallic BSDF) IOR."""
    out = [Closure("lambert")]
    out += [Closure("retro_toon", a, s) for a, s in ((0.15, 0.2), (0.5, 0.6))]
    out += [Closure("glossy", roughness=r) for r in eevee.ROUGHNESS]
    out += [Closure("metallic", ior=n, roughness=r) for n in eevee.IORS for r in eevee.ROUGHNESS]
    out += [Closure("oren_nayar", roughness=1.0), Closure("sheen", roughness=0.5)]
    out += [Closure("retro_glossy", roughness=r) for r in RETRO_ROUGHNESS]
    return out


# ---------------------------------------------------------------------- Blender side


def closure_shader(tree, closure: Closure, weight: float = 1.0):
    """The output socket of ``closure`` with a white colour of ``weight``,
    built as the add-on builds it (``addon.nodes``): coloured closures with a
    colour, grey ones (Metallic) through a Mix Shader factor."""
    nodes, links = tree.nodes, tree.links
    kind = closure.kind
    if kind == "metallic":
        node = nodes.new("ShaderNodeBsdfMetallic")
        node.distribution = "BECKMANN"
        node.fresnel_type = "PHYSICAL_CONDUCTOR"
        node.inputs["IOR"].default_value = (closure.ior,) * 3
        node.inputs["Extinction"].default_value = (0.0, 0.0, 0.0)
        node.inputs["Roughness"].default_value = closure.roughness
        mix = nodes.new("ShaderNodeMixShader")
        mix.inputs["Fac"].default_value = weight
        links.new(node.outputs[0], mix.inputs[2])
        return mix.outputs[0]
    if kind in ("lambert", "oren_nayar"):
        node = nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Roughness"].default_value = closure.roughness if kind == "oren_nayar" else 0.0
    elif kind == "retro_toon":
        node = nodes.new("ShaderNodeBsdfToon")
        node.component = "DIFFUSE"
        node.inputs["Size"].default_value = closure.size
        node.inputs["Smooth"].default_value = closure.smooth
        links.new(nodes.new("ShaderNodeNewGeometry").outputs["Incoming"], node.inputs["Normal"])
    elif kind == "glossy":
        node = nodes.new("ShaderNodeBsdfGlossy")
        node.distribution = "BECKMANN"
        node.inputs["Roughness"].default_value = closure.roughness
    elif kind == "retro_glossy":
        node = nodes.new("ShaderNodeBsdfGlossy")
        node.distribution = "GGX"
        node.inputs["Roughness"].default_value = closure.roughness
        links.new(nodes.new("ShaderNodeNewGeometry").outputs["Incoming"], node.inputs["Normal"])
    elif kind == "sheen":
        node = nodes.new("ShaderNodeBsdfSheen")
        node.distribution = "ASHIKHMIN"
        node.inputs["Roughness"].default_value = closure.roughness
    else:
        raise ValueError(f"no calibration node set-up for closure kind {kind!r}")
    node.inputs["Color"].default_value = (weight, weight, weight, 1.0)
    return node.outputs[0]


def sum_shader(tree, terms):
    """Add Shader chain of ``terms`` [(closure, weight)]."""
    total = None
    for closure, weight in terms:
        shader = closure_shader(tree, closure, weight)
        if total is None:
            total = shader
        else:
            add = tree.nodes.new("ShaderNodeAddShader")
            tree.links.new(total, add.inputs[0])
            tree.links.new(shader, add.inputs[1])
            total = add.outputs[0]
    return total


def calibration_scene(size):
    """A new EEVEE scene of ``size`` (x, y) pixels at one sample as the
    calibration renders: no shadows, no ray tracing, no clamping, the film
    filter off, the Standard view transform, a black world."""
    from addon import scenes

    scene = scenes.new_scene(scenes.EEVEE, 1, size)
    scene.eevee.use_shadows = False
    scene.eevee.use_raytracing = False
    scene.eevee.clamp_surface_direct = 0.0
    scene.render.filter_size = 0.0
    scene.view_settings.view_transform = "Standard"
    scenes.add_world(scene, 0.0, name="black")
    return scene


def calibration_material(name, terms):
    """A new material whose surface is the sum of ``terms`` [(closure, weight)]."""
    import bpy

    mat = bpy.data.materials.new(name)
    if mat.node_tree is None:  # Blender 4.x
        mat.use_nodes = True
    tree = mat.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(sum_shader(tree, terms), out.inputs["Surface"])
    return mat


class SphereScene:
    """Spheres in a grid (``objects``), one material each (a list of
    [(closure, weight)] sums; None: no material, for the caller to assign),
    an orthographic camera along +Z, a delta Sun, a black world (built with
    ``addon.scenes``' parts)."""

    def __init__(self, materials, cell=CELL, columns=None):

        from addon import scenes

        columns = columns or math.ceil(math.sqrt(len(materials)))
        rows = math.ceil(len(materials) / columns)
        scene = calibration_scene((columns * cell, rows * cell))
        scene.render.threads_mode = "FIXED"
        scene.render.threads = 1
        settings = scene.render.image_settings
        if hasattr(settings, "media_type"):  # Blender 5.0 on
            settings.media_type = "MULTI_LAYER_IMAGE"
        settings.file_format = "OPEN_EXR_MULTILAYER"
        scene.render.image_settings.color_depth = "32"
        scene.render.image_settings.exr_codec = "ZIP"
        scene.view_layers[0].use_pass_normal = True
        self.cells, self.objects = [], []
        for i, terms in enumerate(materials):
            col, row = i % columns, i // columns
            x, y = (col - (columns - 1) / 2) * 2.2, ((rows - 1) / 2 - row) * 2.2
            sphere = scenes.add_uv_sphere(128, 64, radius=1.0, location=(x, y, 0.0))
            self.objects.append(sphere)
            self.cells.append((row, col))
            if terms is None:
                continue
            sphere.data.materials.append(calibration_material(f"m{i}", terms))
        scenes.add_camera(scene, location=(0.0, 0.0, 10.0), ortho_scale=2.2 * max(columns, rows))
        self.sun = scenes.add_sun(scene, energy=1.0, angle=0.0)
        self.sun.data.use_shadow = False
        self.scene, self.cell, self.columns, self.rows = scene, cell, columns, rows
        self._path = os.path.join(tempfile.mkdtemp(prefix="eevee_calibration"), "render.exr")
        self._normal = None

    def _layers(self):
        """Render and read the passes: {pass.channel: (H, W) array}."""
        import bpy
        import OpenImageIO as oiio

        self.scene.render.filepath = self._path
        bpy.ops.render.render(write_still=True)
        layers = {}
        for sub in range(oiio.ImageBuf(self._path).nsubimages):  # one subimage per pass
            buf = oiio.ImageBuf(self._path, sub, 0)
            pixels = buf.get_pixels(oiio.FLOAT)
            for i, name in enumerate(buf.spec().channelnames):
                layers[name.split(".", 1)[-1]] = pixels[..., i].astype(float)
        return layers

    def surface_normals(self):
        """The spheres' shading normals (H, W, 3), rendered once with every
        material replaced by a new material's default: the Normal pass of a material
        reports its closures' normals, which for a lobe about the view
        direction (``retro_toon``, ``retro_glossy``) is not the surface's."""
        if self._normal is None:
            import bpy

            plain = bpy.data.materials.get("Paint LUT plain") or bpy.data.materials.new("Paint LUT plain")
            layer = self.scene.view_layers[0]
            layer.material_override = plain
            try:
                layers = self._layers()
            finally:
                layer.material_override = None
            self._normal = np.stack([layers[f"Normal.{c}"] for c in "XYZ"], -1)
        return self._normal

    def render(self, gamma, erode=0):
        """Per sphere: (θl, θv, φ, radiance (N, 3)) of its lit pixels, for the
        light at angle ``gamma`` from the view (in the XZ plane) and unit
        irradiance; ``erode``: leave out pixels within that many of the
        sphere's silhouette (EEVEE shades them unlike the surface inside)."""
        normal = self.surface_normals()
        self.sun.rotation_euler = (0.0, -gamma, 0.0)
        layers = self._layers()
        rgb = np.stack([layers[f"Combined.{c}"] for c in "RGB"], -1)
        light = np.array([-math.sin(gamma), 0.0, math.cos(gamma)])
        out = []
        for row, col in self.cells:
            sl = np.s_[row * self.cell : (row + 1) * self.cell, col * self.cell : (col + 1) * self.cell]
            length = np.linalg.norm(normal[sl], axis=-1)
            ok = np.abs(length - 1.0) < 1e-3
            for _ in range(erode):
                inner = ok.copy()
                inner[1:] &= ok[:-1]
                inner[:-1] &= ok[1:]
                inner[:, 1:] &= ok[:, :-1]
                inner[:, :-1] &= ok[:, 1:]
                ok = inner
            n, c = normal[sl][ok] / length[ok][:, None], rgb[sl][ok]
            theta_l, theta_v, phi = geometry(n, light)
            out.append((theta_l, theta_v, phi, c))
        return out


class PlaneScene:
    """Flat squares side by side on the plane z = 0, one closure each (white,
    unit weight), a delta Sun, an orthographic camera, a black world: every
    pixel of a square sees the same (θl, θv, φ), the geometry set as the
    plane oracle sets it (``addon.scenes.Oracle``).  One render gives every
    closure's radiance at one geometry, so grazing geometries, where a
    sphere's pixels thin out toward its silhouette, are measured as densely
    as any other."""

    #: Pixels across the render, and the squares' side and spacing (scene
    #: units): at θv = 75° a square spans 0.26 of its side, about 11 pixels
    #: for the 49 closures (a 7 x 7 grid in a frame 1.5 times its width).
    SIZE, SIDE, PITCH = 640, 1.0, 1.4

    def __init__(self, todo):
        import bpy

        from addon import scenes

        columns = math.ceil(math.sqrt(len(todo)))
        scene = calibration_scene((self.SIZE, self.SIZE))
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        half = self.SIDE / 2
        self.centres = []
        for i, closure in enumerate(todo):
            x = (i % columns - (columns - 1) / 2) * self.PITCH
            y = ((columns - 1) / 2 - i // columns) * self.PITCH
            mesh = bpy.data.meshes.new(f"square{i}")
            corners = [(x + sx * half, y + sy * half, 0.0) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            mesh.from_pydata(corners, [], [(0, 1, 2, 3)])
            square = bpy.data.objects.new(f"square{i}", mesh)
            scene.collection.objects.link(square)
            mesh.materials.append(calibration_material(f"p{i}", [(closure, 1.0)]))
            self.centres.append((x, y))
        # The frame turns with the view about its axis: it spans the grid's diagonal.
        self.camera = scenes.add_camera(scene, ortho_scale=self.PITCH * columns * 1.5)
        self.sun = scenes.add_sun(scene, energy=1.0, angle=0.0)
        self.sun.data.use_shadow = False
        self.scene = scene
        self._path = os.path.join(tempfile.mkdtemp(prefix="eevee_planes"), "render.exr")

    def render(self, theta_l, theta_v, phi):
        """Each closure's radiance (red channel, unit irradiance) at one
        geometry: the mean of the 3 x 3 pixels about its square's centre."""
        import bpy
        import OpenImageIO as oiio
        from bpy_extras.object_utils import world_to_camera_view
        from mathutils import Vector

        from addon import scenes

        scenes.aim(self.sun, self.camera, theta_l, theta_v, phi, distance=20.0)
        bpy.context.view_layer.update()
        self.scene.render.filepath = self._path
        bpy.ops.render.render(write_still=True)
        red = oiio.ImageBuf(self._path).get_pixels(oiio.FLOAT)[..., 0].astype(float)
        out = []
        for x, y in self.centres:
            u, v, _ = world_to_camera_view(self.scene, self.camera, Vector((x, y, 0.0)))
            col, row = int(u * self.SIZE), int((1.0 - v) * self.SIZE)
            out.append(float(red[row - 1 : row + 2, col - 1 : col + 2].mean()))
        return out


#: Geometries the squares are rendered at (degrees): the grazing band where
#: the spheres' tables were measured 15-25% off the plane oracle at the
#: mirror (θl, θv 60-75°), on the tables' nodes and half-way in φ.
PLANE_THETA = (50, 55, 60, 65, 70, 75)
PLANE_PHI = (0, 7.5, 15, 22.5, 30, 45)


def measure_planes(todo):
    """Per closure of ``todo``: (θl, θv, φ, radiance) at the grazing
    geometries ``PLANE_THETA`` x ``PLANE_THETA`` x ``PLANE_PHI``, from
    one render of the squares per geometry."""
    scene = PlaneScene(todo)
    grid = [(a, b, c) for a in PLANE_THETA for b in PLANE_THETA for c in PLANE_PHI]
    values = []
    t0 = time.time()
    for a, b, c in grid:
        values.append(scene.render(*np.radians((a, b, c))))
    print(f"{len(todo)} closures on squares, {len(grid)} renders, {time.time() - t0:.0f} s", flush=True)
    angles = np.radians(np.array(grid, dtype=float)).T.astype(np.float32)
    values = np.array(values, dtype=np.float32).T
    return [(*angles, values[i]) for i in range(len(todo))]


def geometry(normal, light, view=(0.0, 0.0, 1.0)):
    """(θl, θv, φ) of unit normals (N, 3) for a light and a view direction:
    φ the azimuth of the view from the mirror of the light's azimuth."""
    view = np.asarray(view, dtype=float)
    cl, cv = normal @ light, normal @ view
    lt = light - cl[:, None] * normal
    vt = view - cv[:, None] * normal
    cos_phi = -np.sum(lt * vt, axis=1)
    sin_phi = np.sum(np.cross(-lt, vt) * normal, axis=1)
    phi = np.arctan2(sin_phi, cos_phi)
    return np.arccos(np.clip(cl, -1.0, 1.0)), np.arccos(np.clip(cv, -1.0, 1.0)), phi


# ---------------------------------------------------------------------- tables


def bin_ratios(samples, closure):
    """Σ EEVEE / Σ reference per cell of ``lut.render.eevee``'s grid (cell centres
    at the grid nodes), NaN where no pixel fell or the reference is nil."""
    tl = np.concatenate([s[0] for s in samples])
    tv = np.concatenate([s[1] for s in samples])
    ph = np.abs(np.concatenate([s[2] for s in samples]))
    value = np.concatenate([s[3] for s in samples])
    ref = eevee.reference(closure, tl, tv, ph)
    keep = (tl < np.radians(89.0)) & (tv < np.radians(89.0))
    idx = [
        np.clip(np.rint(np.interp(a, g, np.arange(g.size))), 0, g.size - 1).astype(int)
        for a, g in ((tl, eevee.THETA), (tv, eevee.THETA), (ph, eevee.PHI))
    ]
    shape = (eevee.THETA.size, eevee.THETA.size, eevee.PHI.size)
    flat = np.ravel_multi_index(idx, shape)[keep]
    num = np.bincount(flat, value[keep], np.prod(shape)).reshape(shape)
    den = np.bincount(flat, ref[keep], np.prod(shape)).reshape(shape)
    count = np.bincount(flat, None, np.prod(shape)).reshape(shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where((den > 1e-6 * max(den.max(), 1e-300)) & (count >= 3), num / den, np.nan)
    return ratio, count


def fitted_table(closure, sample, planes=None):
    """The table of ``closure`` from its sphere pixels ``sample`` (θl, θv, φ,
    radiance) and its squares' geometries ``planes`` (the same, or None):
    the least-squares fit of ``lut.render.eevee.fit_table`` about the binned
    ratios of the spheres, pixels within 1° of the horizon left out as in
    ``bin_ratios``.  Where the squares measure (their geometries' box,
    half a cell beyond it), the spheres' pixels are left out: they are the
    pixels next to the silhouette, which EEVEE shades unlike a flat surface
    at the same angles (``scripts/eevee_table_check.py`` measured those
    tables 15-25% off the plane oracle at the grazing mirror).  A square's
    geometry counts as many pixels as the median cell the spheres reach."""
    ratio, count = bin_ratios([sample], closure)
    prior = eevee.fill(ratio)
    tl, tv, ph, value = (np.asarray(a, dtype=float) for a in sample)
    keep = (tl < np.radians(89.0)) & (tv < np.radians(89.0))
    tl, tv, ph, value = tl[keep], tv[keep], ph[keep], value[keep]
    weight = np.ones(tl.size)
    if planes is not None:
        lo, hi = np.radians(PLANE_THETA[0] - 2.5), np.radians(PLANE_THETA[-1] + 2.5)
        box = (tl >= lo) & (tl <= hi) & (tv >= lo) & (tv <= hi) & (np.abs(ph) <= np.radians(PLANE_PHI[-1] + 7.5))
        tl, tv, ph, value, weight = tl[~box], tv[~box], ph[~box], value[~box], weight[~box]
        extra = [np.asarray(a, dtype=float) for a in planes]
        finite = np.isfinite(extra[3])
        extra = [a[finite] for a in extra]
        tl, tv, ph, value = (np.concatenate([a, b]) for a, b in zip((tl, tv, ph, value), extra, strict=True))
        weight = np.concatenate([weight, np.full(extra[0].size, float(np.median(count[count > 0])))])
    return eevee.fit_table(closure, tl, tv, ph, value, prior, weight=weight)


def write_module(path, version, tables, merge=False):
    """Write ``lut/render/eevee_tables.py``: the tables of ``version`` replace that
    line's (``merge``: are added to that line's, replacing only those of the
    same keys), other lines' are kept."""
    path = pathlib.Path(path)
    stored = {}
    if path.exists():
        scope = {}
        exec(compile(path.read_text(), str(path), "exec"), scope)
        stored = dict(scope["TABLES"])
    if merge and version in stored:
        tables = {**eevee.decode(stored[version]), **tables}
    stored[version] = eevee.encode(tables)
    lines = [
        '"""EEVEE calibration tables by Blender line, made by scripts/calibrate_eevee.py',
        "(do not edit): for each line, the base64 of a compressed .npz (numpy alone reads",
        'it: lut.render.eevee.decode) of per-closure ratio tables on lut.render.eevee\'s grid."""',
        "",
        "# ruff: noqa: E501",
        "# fmt: off",
        "TABLES = {",
        *(f"    {v!r}: {stored[v]!r}," for v in sorted(stored)),
        "}",
        "",
    ]
    files.atomic_write_text(path, "\n".join(lines))


def measure(todo, per_render=25):
    """Per closure of ``todo``: its pixels' (θl, θv, φ, EEVEE radiance of
    the red channel) over the sweep of γ, as four float32 arrays."""
    out = []
    for start in range(0, len(todo), per_render):
        batch = todo[start : start + per_render]
        scene = SphereScene([[(c, 1.0)] for c in batch])
        samples = [[] for _ in batch]
        t0 = time.time()
        for gamma in GAMMAS:
            for i, s in enumerate(scene.render(math.radians(gamma), erode=ERODE)):
                samples[i].append(s)
        print(f"{len(batch)} closures, {len(GAMMAS)} renders, {time.time() - t0:.0f} s", flush=True)
        for s in samples:
            out.append(
                tuple(np.concatenate([x[j] if j < 3 else x[3][:, 0] for x in s]).astype(np.float32) for j in range(4))
            )
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=pathlib.Path, default=MODULE)
    parser.add_argument("--per-render", type=int, default=25, help="spheres per render")
    parser.add_argument("--raw", type=pathlib.Path, help="also keep the pixels' samples in this .npz")
    parser.add_argument("--from-raw", type=pathlib.Path, help="make the tables from samples kept by --raw")
    parser.add_argument(
        "--only",
        nargs="+",
        choices=eevee.KINDS,
        metavar="KIND",
        help="measure only these closure kinds, keeping the line's other tables",
    )
    args = parser.parse_args(argv)
    todo = [c for c in calibration_closures() if not args.only or c.kind in args.only]
    if args.from_raw:
        raw = np.load(args.from_raw)
        version = str(raw["version"])
        samples = [tuple(raw[f"{eevee.table_key(c)}/{j}"] for j in range(4)) for c in todo]
        # Raw samples kept before the squares were measured have none: spheres alone.
        keys = [f"{eevee.table_key(c)}/plane" for c in todo]
        planes = [tuple(raw[f"{k}/{j}"] for j in range(4)) if f"{k}/0" in raw.files else None for k in keys]
    else:
        import bpy

        version = "{}.{}".format(*bpy.app.version[:2])
        samples = measure(todo, args.per_render)
        planes = measure_planes(todo)
        if args.raw:
            flat = {f"{eevee.table_key(c)}/{j}": s[j] for c, s in zip(todo, samples, strict=True) for j in range(4)}
            for c, s in zip(todo, planes, strict=True):
                flat |= {f"{eevee.table_key(c)}/plane/{j}": s[j] for j in range(4)}
            np.savez_compressed(args.raw, version=version, **flat)
    tables = {eevee.table_key(c): fitted_table(c, s, p) for c, s, p in zip(todo, samples, planes, strict=True)}
    write_module(args.out, version, tables, merge=bool(args.only))
    print(f"wrote {len(tables)} tables for Blender {version} to {args.out}")


if __name__ == "__main__":
    main()
