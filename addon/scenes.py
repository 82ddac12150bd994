"""Blender scenes that measure paint materials: one module for the tests and
the scripts, shipped so that a LUT can be checked against its model in the
Blender that renders it.

* ``Oracle``: Cycles as an exact BRDF oracle.  A large plane at the origin, a
  delta Sun lamp (angle 0, strength E in W/m²), an orthographic camera
  looking at the plane's centre and a black world: the rendered radiance is
  f(l, v)·E·cos θl exactly, at one sample.  Denoising must be off: Cycles
  enables it by default for final renders, which perturbs the channels by
  ~1%.  Renders are read back from 32-bit EXR with OpenImageIO, so no colour
  management is involved.  With EEVEE it is a measurement, not an oracle.
* ``relative_rms`` over ``GRID`` (``GRID_EEVEE``: a coarse subgrid): the
  fidelity measure (``lut.render.measure``), whole (``oracle_errors``: and
  over the grazing band);
  ``paints``: the paints it is reported on; ``paint_material``,
  ``principled`` and ``principled_params_material``: materials on the plane.
* ``sphere_scene``: a sphere under a Sun for render timings;
  ``presets_scene``: three spheres on a floor (the README's picture).

Every scene starts from an empty factory-settings file: building one
replaces the open file (and resets the preferences), so this is for
background sessions, not an artist's file."""

from __future__ import annotations

import math
import os
import tempfile

import bpy
import numpy as np
from mathutils import Vector

from . import api
from ._lut import lut, measure

#: The oracle's image size (pixels across); every pixel sees the same directions.
RESOLUTION = 8

#: The oracle's geometries: the fidelity measure's own grid
#: (``lut.render.measure.GRID``: θl 0-75° and θv 5-75° in 5° steps, φ 0-180°
#: in 10°), for a smooth paint less the geometries within
#: ``measure.MIRROR_EXCLUSION`` of the mirror (``grid_points``), so a Cycles
#: render measures what the fit reports.  About 4500 renders of 8x8 pixels,
#: some 40 s a paint.  A coarser subgrid weighs a sharp lobe's peak
#: otherwise: θl, θv in 15° steps and φ in 30° ones put the near-mirror
#: geometries at φ = 0 at a seventh of the grid instead of a nineteenth and
#: read the fit of a slope-0.1 exponential paint as 1.7% where the measure
#: is 4.1%, a green CARC's as 6.8% where it is 5.2%.
GRID = measure.GRID
#: A coarse subgrid of it for EEVEE, whose renders take seconds, not
#: milliseconds (not the measure: a sample of it).
GRID_EEVEE = (np.radians([0, 30, 60, 75]), np.radians([5, 35, 65, 75]), np.radians([0, 90, 180]))

#: EEVEE's engine id: BLENDER_EEVEE_NEXT in Blender 4.2-4.5.
EEVEE = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"


# ----------------------------------------------------------------------------- parts every scene uses


def new_scene(engine, samples, size, denoise=False, reset=True):
    """The scene to build in: after an empty factory-settings file
    (``reset``; else the open file's scene), rendering with ``engine`` on the
    CPU at ``samples`` per pixel (Cycles and EEVEE), ``size`` (x, y) pixels,
    Cycles' denoiser on or off (``denoise``; None: as the file has it)."""
    if reset:
        bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = engine
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    if denoise is not None:
        scene.cycles.use_denoising = denoise
    scene.eevee.taa_render_samples = samples
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def add_world(scene, strength, colour=None, name="world"):
    """A uniform world of ``strength`` (and ``colour``, else Blender's grey)."""
    world = bpy.data.worlds.new(name)
    scene.world = world
    if world.node_tree is None:  # Blender 4.x
        world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    if colour is not None:
        background.inputs["Color"].default_value = (*colour, 1.0)
    background.inputs["Strength"].default_value = strength
    return world


def add_sun(scene, energy=None, angle=None, rotation=(0.0, 0.0, 0.0)):
    """A Sun lamp object (``energy`` in W/m², ``angle`` its disc's; None:
    Blender's defaults), rotated by ``rotation`` (Euler, radians)."""
    light = bpy.data.lights.new("sun", "SUN")
    if energy is not None:
        light.energy = energy
    if angle is not None:
        light.angle = angle
    sun = bpy.data.objects.new("sun", light)
    sun.rotation_euler = rotation
    scene.collection.objects.link(sun)
    return sun


def add_camera(scene, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), ortho_scale=None, lens=None):
    """The scene's camera: orthographic of ``ortho_scale`` when given, else
    perspective (``lens`` in mm, or Blender's default)."""
    data = bpy.data.cameras.new("camera")
    if ortho_scale is not None:
        data.type = "ORTHO"
        data.ortho_scale = ortho_scale
    if lens is not None:
        data.lens = lens
    camera = bpy.data.objects.new("camera", data)
    camera.location = location
    camera.rotation_euler = rotation
    scene.collection.objects.link(camera)
    scene.camera = camera
    return camera


def aim(sun, camera, theta_l, theta_v, phi, distance=5.0):
    """Set one geometry of ``lut.models``' convention on a scene lying in the
    plane z = 0: the Sun at θl from the normal in the plane y = 0 (the
    model's source at azimuth π; the Sun points along -Z rotated about Y),
    and the camera ``distance`` away along the view (θv, φ: φ = 0 is the
    mirror side), looking at the origin."""
    sun.rotation_euler = (0.0, -theta_l, 0.0)
    view = Vector((math.sin(theta_v) * math.cos(phi), math.sin(theta_v) * math.sin(phi), math.cos(theta_v)))
    camera.location = distance * view
    camera.rotation_euler = view.to_track_quat("Z", "Y").to_euler()


def add_uv_sphere(segments, ring_count, **options):
    """A smooth-shaded UV sphere (``bpy.ops.mesh.primitive_uv_sphere_add``'s options)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=ring_count, **options)
    sphere = bpy.context.object
    bpy.ops.object.shade_smooth()
    return sphere


# ----------------------------------------------------------------------------- the oracle and the fidelity measure


def paints():
    """The paints the fidelity is measured on: the smooth and rough (satin,
    matte) cases and the three presets."""
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
    its own approximations of the closures; one sample per pixel).
    ``reset``: start from an empty factory-settings file (which also resets
    the preferences); False builds in the open file's scene, e.g. after an
    extension was installed in this session."""

    def __init__(self, irradiance=3.0, engine="CYCLES", reset=True):
        scene = new_scene(engine, 1, (RESOLUTION, RESOLUTION), reset=reset)
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.image_settings.exr_codec = "ZIP"
        add_world(scene, 0.0, name="black")
        mesh = bpy.data.meshes.new("plane")
        mesh.from_pydata([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)], [], [(0, 1, 2, 3)])
        self.plane = bpy.data.objects.new("plane", mesh)
        scene.collection.objects.link(self.plane)
        self.camera = add_camera(scene, ortho_scale=0.5)
        self.sun = add_sun(scene, energy=irradiance, angle=0.0)
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
        aim(self.sun, self.camera, theta_l, theta_v, phi)
        self.scene.render.filepath = self._path
        bpy.ops.render.render(write_still=True)
        try:
            import OpenImageIO as oiio
        except ImportError:  # Blender 4.2-4.3: the library's own EXR reader
            from ._lut import exr

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
        # Every pixel sees these directions: their mean is the render's mean
        # over samples where EEVEE picks closures at random per pixel (a
        # converged fit), and any one pixel where it does not.
        return self.image(theta_l, theta_v, phi).mean(axis=(0, 1))

    def brdf(self, theta_l, theta_v, phi):
        """The rendered BRDF: radiance / (E cos θl)."""
        return self.radiance(theta_l, theta_v, phi) / (self.irradiance * math.cos(theta_l))


def grid_points(paint, grid=GRID):
    """The (θl, θv, φ) geometries of ``grid`` the measure counts for
    ``paint``: all of them for a rough paint, those at least
    ``measure.MIRROR_EXCLUSION`` from the mirror for a smooth one."""
    return measure.points(paint.slope == 0, grid)


def oracle_errors(oracle, paint, grid=GRID, best_scale=False, points=None) -> tuple[float, float]:
    """The fidelity measure (``lut.render.measure``) of the plane's material:
    rendered radiance against ``paint.brdf`` · cos θl at ``grid_points``
    (or at ``points``, (θl, θv, φ) arrays, when given), (whole, grazing band
    θl >= 60°).  ``best_scale``: after the one overall factor that minimizes
    the whole figure (a baseline's most favourable exposure)."""
    tl, tv, ph = grid_points(paint, grid) if points is None else (np.asarray(a, dtype=float) for a in points)
    got = np.array([oracle.radiance(*g) / oracle.irradiance for g in zip(tl, tv, ph, strict=True)])
    ref = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
    scale = np.sum(got * ref) / np.sum(got * got) if best_scale else 1.0
    return measure.errors(scale * got, ref, tl)


def relative_rms(oracle, paint, grid=GRID, best_scale=False) -> float:
    """The fidelity measure of the plane's material over ``grid``, whole
    (``oracle_errors``' first figure)."""
    return oracle_errors(oracle, paint, grid, best_scale)[0]


def paint_material(oracle, paint, directory, name="paint", **options):
    """A material on the plane rendering ``paint`` through the add-on (set
    and baked in ``directory``); returns (material, lut.render.bake.RenderBake)."""
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
    """A Principled BSDF (single-scatter GGX) with ``lut.render.principled``
    parameters on the plane: the export fallback as Cycles renders it."""
    mat = oracle.material("fallback")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.distribution = "GGX"
    for name, value in params.node_inputs().items():
        bsdf.inputs[name].default_value = value
    links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


# ----------------------------------------------------------------------------- pictures and timings


def sphere_scene(size, samples, engine="CYCLES"):
    """A UV sphere (64 × 32, smooth) lit by a Sun and a dim world, seen by a
    perspective camera, ``size``² pixels, no denoising; renders go to a
    temporary PNG.  Returns (scene, sphere)."""
    scene = new_scene(engine, samples, (size, size))
    scene.render.filepath = os.path.join(tempfile.mkdtemp(), "cost.png")
    add_world(scene, 0.3)
    sphere = add_uv_sphere(64, 32)
    add_camera(scene, location=(0, -4, 0), rotation=(1.5708, 0, 0))
    add_sun(scene, rotation=(0.6, 0.3, 0.0))
    return scene, sphere


def presets_scene(width, height, samples):
    """Three spheres on a grey floor (Cycles, PNG, the 'Standard' view so
    colours are shown as rendered), lit by a Sun and a soft sky.  Returns
    (scene, spheres) with the spheres left to right, without materials."""
    scene = new_scene("CYCLES", samples, (width, height), denoise=None)
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    add_world(scene, 0.35, colour=(0.55, 0.65, 0.8), name="sky")
    tilt = math.radians(90 - math.degrees(math.atan2(2.4, 11.0)))
    add_camera(scene, location=(0.0, -11.0, 2.4), rotation=(tilt, 0.0, 0.0), lens=50)
    add_sun(
        scene, energy=3.0, angle=math.radians(3.0), rotation=(math.radians(40), math.radians(-25), math.radians(-20))
    )
    bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, -1))
    floor = bpy.data.materials.new("floor")
    floor.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    bpy.context.object.data.materials.append(floor)
    spheres = [add_uv_sphere(96, 48, radius=1.0, location=(2.3 * (i - 1), 0, 0)) for i in range(3)]
    return scene, spheres
