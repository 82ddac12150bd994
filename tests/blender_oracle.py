"""Cycles as an exact BRDF oracle (test infrastructure for the add-on).

A large plane at the origin, a delta Sun lamp (angle 0, strength E in W/m²),
an orthographic camera looking at the plane's centre and a black world: the
rendered radiance is f(l, v)·E·cos θl exactly, at one sample.  Denoising must
be off: Cycles enables it by default for final renders, which perturbs the
channels by ~1%.  Renders are read back from 32-bit EXR with OpenImageIO, so
no colour management is involved."""

from __future__ import annotations

import math
import os
import tempfile

import bpy
import numpy as np
from mathutils import Vector

RESOLUTION = 8


#: The fidelity measure's geometries: θl, θv <= 75° and azimuths away from
#: the exact mirror direction (φ = 0).
GRID = (np.radians([0, 15, 30, 45, 60, 75]), np.radians([5, 20, 35, 50, 65, 75]), (0.4, 1.1, 1.9, 2.6, 3.1))
#: A coarser grid for EEVEE, whose renders take seconds, not milliseconds.
GRID_EEVEE = (np.radians([0, 30, 60, 75]), np.radians([5, 35, 65, 75]), (0.4, 1.9, 3.1))

#: EEVEE's engine id: BLENDER_EEVEE_NEXT in Blender 4.2-4.5.
EEVEE = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"


def paints():
    """The paints the fidelity is measured on: the issue's smooth and rough
    (satin, matte) cases and the three presets."""
    import lut

    orange = {"rho": (0.8, 0.4, 0.1), "single": 0.3, "g": 0.3}
    return {
        "glossy white": lut.preset("glossy_white"),
        "smooth single": lut.Paint(**orange),
        "satin": lut.Paint(**orange, slope=0.25),
        "matte": lut.Paint(**orange, slope=2.0, distribution="exponential"),
        "glossy red": lut.preset("glossy_red"),
        "green CARC": lut.preset("green_carc"),
    }


class Oracle:
    """engine "CYCLES" (exact: one sample, no denoising) or EEVEE (not exact:
    its own approximations of the closures; one sample per pixel)."""

    def __init__(self, irradiance=3.0, engine="CYCLES"):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = bpy.context.scene
        scene.render.engine = engine
        scene.cycles.device = "CPU"
        scene.cycles.samples = 1
        scene.cycles.use_denoising = False
        if engine != "CYCLES":
            scene.eevee.taa_render_samples = 1
        scene.render.resolution_x = scene.render.resolution_y = RESOLUTION
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.image_settings.exr_codec = "ZIP"
        world = bpy.data.worlds.new("black")
        scene.world = world
        if world.node_tree is None:  # Blender 4.x
            world.use_nodes = True
        world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
        mesh = bpy.data.meshes.new("plane")
        mesh.from_pydata([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)], [], [(0, 1, 2, 3)])
        self.plane = bpy.data.objects.new("plane", mesh)
        scene.collection.objects.link(self.plane)
        cam = bpy.data.cameras.new("camera")
        cam.type = "ORTHO"
        cam.ortho_scale = 0.5
        self.camera = bpy.data.objects.new("camera", cam)
        scene.collection.objects.link(self.camera)
        scene.camera = self.camera
        sun = bpy.data.lights.new("sun", "SUN")
        sun.energy = irradiance
        sun.angle = 0.0
        self.sun = bpy.data.objects.new("sun", sun)
        scene.collection.objects.link(self.sun)
        self.irradiance = irradiance
        self.scene = scene
        self._path = os.path.join(tempfile.mkdtemp(prefix="oracle"), "render.exr")

    def material(self, name="oracle"):
        """A new material with an empty node tree and an output node, on the plane."""
        mat = bpy.data.materials.new(name)
        if mat.node_tree is None:  # Blender 4.x
            mat.use_nodes = True
        nodes = mat.node_tree.nodes
        for node in list(nodes):
            nodes.remove(node)
        nodes.new("ShaderNodeOutputMaterial")
        self.plane.data.materials.clear()
        self.plane.data.materials.append(mat)
        return mat

    def image(self, theta_l, theta_v, phi):
        """The whole rendered image (RESOLUTION², RGB) for one geometry: every
        pixel of the plane sees the same directions."""
        self.sun.rotation_euler = (0.0, -theta_l, 0.0)
        view = Vector((math.sin(theta_v) * math.cos(phi), math.sin(theta_v) * math.sin(phi), math.cos(theta_v)))
        self.camera.location = 5.0 * view
        self.camera.rotation_euler = view.to_track_quat("Z", "Y").to_euler()
        self.scene.render.filepath = self._path
        bpy.ops.render.render(write_still=True)
        try:
            import OpenImageIO as oiio
        except ImportError:  # Blender 4.2-4.3: lut's own EXR reader
            from lut import exr

            pixels = exr.read(self._path)[0]
        else:
            pixels = oiio.ImageBuf(self._path).get_pixels(oiio.FLOAT)
        return np.asarray(pixels[..., :3], dtype=float)

    def radiance(self, theta_l, theta_v, phi):
        """RGB radiance toward a viewer at polar angle θv and azimuth φ from
        the light's plane (φ = 0: the viewer on the far side, the mirror
        direction when θv = θl); equals f·E·cos θl."""
        # Light travels towards -ω_l with ω_l = (-sin θl, 0, cos θl), i.e. the
        # model's source at azimuth π; the sun points along -Z rotated about Y.
        return self.image(theta_l, theta_v, phi)[RESOLUTION // 2, RESOLUTION // 2]

    def brdf(self, theta_l, theta_v, phi):
        """The rendered BRDF: radiance / (E cos θl)."""
        return self.radiance(theta_l, theta_v, phi) / (self.irradiance * math.cos(theta_l))


def relative_rms(oracle, paint, grid=GRID, best_scale=False) -> float:
    """Rendered radiance of the plane's material against ``paint.brdf`` ·
    cos θl over ``grid``: the cos-weighted relative RMS (the acceptance
    measure).  ``best_scale``: after the one overall factor that minimizes
    it (a baseline's most favourable exposure)."""
    got, ref, weight = [], [], []
    for tl in grid[0]:
        for tv in grid[1]:
            for phi in grid[2]:
                got.append(oracle.radiance(tl, tv, phi) / oracle.irradiance)
                ref.append(paint.brdf(tl, tv, phi) * math.cos(tl))
                weight.append(math.cos(tl))
    got, ref, weight = np.array(got), np.array(ref), np.array(weight)[:, None]
    scale = np.sum(got * ref * weight**2) / np.sum((got * weight) ** 2) if best_scale else 1.0
    return float(np.sqrt(np.sum(((scale * got - ref) * weight) ** 2) / np.sum((ref * weight) ** 2)))


def paint_material(oracle, paint, directory, name="paint", **options):
    """A material on the plane rendering ``paint`` through the add-on (set
    and baked in ``directory``); returns (material, lut.render.RenderBake)."""
    from addon import api

    material = oracle.material(name)
    api.set_paint(material, paint)
    result = api.bake_material(material, directory=directory, **options)
    return material, result


def principled(oracle, paint):
    """The baseline an artist would build without Paint LUT: a Principled BSDF
    with the paint's diffuse colour ρ (as RGB), IOR n and roughness sqrt(slope) (the
    Beckmann roughness that gives the paper's Gaussian facet term), on the plane."""
    mat = oracle.material("principled")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    rho = paint.rho.rgb(paint.space) if hasattr(paint.rho, "rgb") else np.asarray(paint.rho, dtype=float)
    bsdf.inputs["Base Color"].default_value = (*rho, 1.0)
    bsdf.inputs["IOR"].default_value = float(paint.index_at(589.3))
    bsdf.inputs["Roughness"].default_value = min(1.0, math.sqrt(paint.slope))
    links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def principled_params_material(oracle, params):
    """A Principled BSDF (single-scatter GGX) with ``lut.principled``
    parameters on the plane: the export fallback as Cycles renders it."""
    mat = oracle.material("fallback")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.distribution = "GGX"
    for name, value in params.node_inputs().items():
        bsdf.inputs[name].default_value = value
    links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat
