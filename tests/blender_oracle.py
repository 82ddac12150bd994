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


class Oracle:
    def __init__(self, irradiance=3.0):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = bpy.context.scene
        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = 1
        scene.cycles.use_denoising = False
        scene.render.resolution_x = scene.render.resolution_y = RESOLUTION
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        world = bpy.data.worlds.new("black")
        scene.world = world
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
        nodes = mat.node_tree.nodes
        for node in list(nodes):
            nodes.remove(node)
        nodes.new("ShaderNodeOutputMaterial")
        self.plane.data.materials.clear()
        self.plane.data.materials.append(mat)
        return mat

    def radiance(self, theta_l, theta_v, phi):
        """RGB radiance toward a viewer at polar angle θv and azimuth φ from
        the light's plane (φ = 0: the viewer on the far side, the mirror
        direction when θv = θl); equals f·E·cos θl."""
        # Light travels towards -ω_l with ω_l = (-sin θl, 0, cos θl), i.e. the
        # model's source at azimuth π; the sun points along -Z rotated about Y.
        self.sun.rotation_euler = (0.0, -theta_l, 0.0)
        view = Vector((math.sin(theta_v) * math.cos(phi), math.sin(theta_v) * math.sin(phi), math.cos(theta_v)))
        self.camera.location = 5.0 * view
        self.camera.rotation_euler = view.to_track_quat("Z", "Y").to_euler()
        self.scene.render.filepath = self._path
        bpy.ops.render.render(write_still=True)
        import OpenImageIO as oiio

        pixels = oiio.ImageBuf(self._path).get_pixels(oiio.FLOAT)
        return np.asarray(pixels[RESOLUTION // 2, RESOLUTION // 2, :3], dtype=float)

    def brdf(self, theta_l, theta_v, phi):
        """The rendered BRDF: radiance / (E cos θl)."""
        return self.radiance(theta_l, theta_v, phi) / (self.irradiance * math.cos(theta_l))
