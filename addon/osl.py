"""Cycles' OSL variant of a paint group: the Script node that draws the
signed ramp closures (``lut.render.fitting.fit_osl``), and whether a scene
renders it.

The shader (``shaders/paint_lut_ramps.osl``) is compiled into the node
(mode Internal: the bytecode is stored in the .blend), so a render farm
needs no file beside the .blend.  In Blender the source is also kept as a
text of the .blend, and Blender compiles it and makes the sockets when the
node's script is set; the ``bpy`` module cannot (its OSL query module is
not importable, and setting the script would only report that), so there
the shader is compiled with Cycles' own compiler and the sockets are made
from the compiled parameters.

Open Shading Language runs on the CPU and with OptiX only.  Where a scene
renders with SVM (OSL off, or a GPU without OptiX) Cycles leaves a Script
node out: the group renders its SVM closures alone, which are exactly the
type's SVM fit (the variant keeps them unchanged), so nothing needs
rewiring; ``renders_osl`` says which the scene draws."""

from __future__ import annotations

import hashlib
import importlib.util
import pathlib
import tempfile

import bpy

SOURCE = pathlib.Path(__file__).resolve().parent / "shaders" / "paint_lut_ramps.osl"
TEXT_NAME = "paint_lut_ramps.osl"
OUTPUT = "Ramps"
#: The shader's ramps: the diffuse ramp, a Phong ramp per exponent (in the
#: order of a fit's ramp families, ``closures.ramp_closures``) and the
#: diffuse ramp about the view.
FAMILIES = ("D", "P", "Q", "R")
#: The shader's letter of each ramp kind drawn once (the Phong ramps take
#: the remaining letters in order).
KIND_FAMILY = {"diffuse_ramp": "D", "retro_ramp": "R"}
#: The Phong ramps' exponent inputs.
EXPONENTS = {"P": "P_exponent", "Q": "Q_exponent"}
AMPLITUDES = {"facet": "Facet", "single": "Single", "diffuse": "Diffuse"}


def weight_input(family: str, component: str, trio: int) -> str:
    """The Script node input that takes three knots' weights of one ramp and
    component (knots 3·trio to 3·trio + 2 in R, G, B)."""
    return f"{family}_{component}_{trio}"


def script_text():
    """The shader source as a text of the .blend (refreshed when the
    shipped source changed)."""
    source = SOURCE.read_text()
    text = bpy.data.texts.get(TEXT_NAME)
    if text is None:
        text = bpy.data.texts.new(TEXT_NAME)
    if text.as_string() != source:
        text.clear()
        text.write(source)
    return text


def _compiled():
    """The shader's bytecode and its parameters [(type, name)], compiled by
    Cycles' oslc."""
    import _cycles

    with tempfile.TemporaryDirectory() as tmp:
        oso = pathlib.Path(tmp) / "paint_lut_ramps.oso"
        if not _cycles.osl_compile(str(SOURCE), str(oso)):
            raise RuntimeError(f"Cycles could not compile {SOURCE.name}")
        bytecode = oso.read_text()
    params = []
    for line in bytecode.splitlines():
        fields = line.split("\t")
        if fields[0] in ("param", "oparam"):
            params.append((fields[0], fields[1], fields[2]))
    return bytecode, params


_SOCKETS = {"vector": "NodeSocketVector", "float": "NodeSocketFloat", "closure color": "NodeSocketShader"}


def ramps_node(tree):
    """A Script node of the ramps shader in ``tree``, compiled, with its
    sockets."""
    node = tree.nodes.new("ShaderNodeScript")
    node.mode = "INTERNAL"
    node.label = "OSL ramps (Cycles CPU / OptiX)"
    if importlib.util.find_spec("oslquery") is not None:
        node.script = script_text()  # Blender compiles it and makes the sockets
    if OUTPUT not in node.outputs:  # the bpy module: Cycles' compiler, sockets by hand
        bytecode, params = _compiled()
        for kind, type_, name in params:
            sockets = node.outputs if kind == "oparam" else node.inputs
            if name not in sockets:
                sockets.new(_SOCKETS[type_], name, identifier=name)
        node.bytecode = bytecode
        node.bytecode_hash = hashlib.md5(bytecode.encode()).hexdigest()
    return node


def renders_osl(scene) -> bool:
    """Whether Cycles draws OSL in this scene: Open Shading Language on, and
    the CPU or an OptiX GPU (other GPUs render SVM)."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None or not getattr(cycles, "shading_system", False):
        return False
    if getattr(cycles, "device", "CPU") == "CPU":
        return True
    try:
        prefs = bpy.context.preferences.addons["cycles"].preferences
    except (KeyError, AttributeError):
        return False
    return getattr(prefs, "compute_device_type", "NONE") == "OPTIX"


def set_shading(scene, on: bool = True) -> None:
    """Turn Cycles' Open Shading Language on or off in a scene."""
    scene.cycles.shading_system = bool(on)
