"""Node groups that render a paint: closures weighted per view angle.

The group reads the closure weights w_k(θv) from a small Non-Color EXR
(lut.closures.save_weights) at u = cos θv (Geometry Incoming · Normal) and
row k, and sums the weighted closures; the smooth interface's mirror
reflection is a Metallic BSDF (physical conductor, IOR n, no extinction,
roughness 0: the exact dielectric Fresnel mirror in Blender 5.0) scaled by the
facet weight, and rough paints' facet lobes are Metallic BSDFs of Beckmann
roughness (on Blender 4.2-4.5: Principled GGX lobes) scaled by their (grey)
weights.  A material gets one group per render engine, each into a Material
Output targeted at it (Cycles, EEVEE: lut.closures.TARGETS)."""

from __future__ import annotations

import bpy

from lut import closures

GROUP_PREFIX = "Paint LUT"

#: The Metallic BSDF's physical conductor Fresnel is the exact dielectric
#: Fresnel for extinction 0 from Blender 5.0 on; 4.3-4.5 use an approximate
#: conductor Fresnel (1.29-1.50x off for k = 0) and 4.2 has no Metallic BSDF.
#: There the facet lobes are Principled BSDFs with a black base (exact
#: dielectric Fresnel, GGX: lut.closures' "ggx" kind, fitted as such), as in
#: every EEVEE group, and the mirror is a Principled BSDF of roughness 0.
EXACT_METALLIC = bpy.app.version >= (5, 0, 0)


def _image(path):
    """The weights image, read as data (Non-Color), referenced relative to
    the .blend file when it is saved so a render farm finds it."""
    image = bpy.data.images.load(str(path), check_existing=False)
    image.colorspace_settings.name = "Non-Color"
    if bpy.data.filepath:
        image.filepath = bpy.path.relpath(str(path))
    return image


def build_group(name, fitted: closures.Fit, weights_path, n):
    """A shader node group rendering ``fitted`` (replaces a group of the same name)."""
    old = bpy.data.node_groups.get(name)
    if old is not None:
        bpy.data.node_groups.remove(old)
    group = bpy.data.node_groups.new(name, "ShaderNodeTree")
    group.interface.new_socket(name="Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    nodes, links = group.nodes, group.links
    out = nodes.new("NodeGroupOutput")
    geometry = nodes.new("ShaderNodeNewGeometry")
    dot = nodes.new("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    links.new(geometry.outputs["Incoming"], dot.inputs[0])
    links.new(geometry.outputs["Normal"], dot.inputs[1])
    views = len(fitted.cos_view)
    # Texel centres: column j at u = (j + 0.5)/M holds cos θv = j/(M - 1).
    to_u = nodes.new("ShaderNodeMath")
    to_u.operation = "MULTIPLY_ADD"
    to_u.use_clamp = True
    links.new(dot.outputs["Value"], to_u.inputs[0])
    to_u.inputs[1].default_value = (views - 1) / views
    to_u.inputs[2].default_value = 0.5 / views
    image = _image(weights_path)
    rows = len(fitted.basis)
    total = None
    for k, closure in enumerate(fitted.basis):
        coord = nodes.new("ShaderNodeCombineXYZ")
        links.new(to_u.outputs[0], coord.inputs["X"])
        coord.inputs["Y"].default_value = (k + 0.5) / rows
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.interpolation = "Linear"
        tex.extension = "EXTEND"
        links.new(coord.outputs[0], tex.inputs["Vector"])
        if closure.grey:
            # No colour input: scale by a Mix Shader factor (the fit keeps
            # grey weights <= 1, where the factor clamps).
            lobe = nodes.new("ShaderNodeMixShader")
            links.new(tex.outputs["Color"], lobe.inputs["Fac"])  # grey: every channel is the weight
            make = _metallic if closure.kind == "metallic" else _principled_specular
            links.new(make(nodes, closure.ior, closure.roughness).outputs[0], lobe.inputs[2])
            total = lobe if total is None else _add(nodes, links, total, lobe)
            continue
        bsdf = _closure_node(nodes, closure)
        links.new(tex.outputs["Color"], bsdf.inputs["Color"])
        total = bsdf if total is None else _add(nodes, links, total, bsdf)
    if fitted.mirror > 0:
        mirror = (_metallic if EXACT_METALLIC else _principled_specular)(nodes, n, 0.0)
        scaled = nodes.new("ShaderNodeMixShader")
        scaled.inputs["Fac"].default_value = fitted.mirror
        links.new(mirror.outputs[0], scaled.inputs[2])  # fac·mirror + (1 - fac)·nothing
        total = _add(nodes, links, total, scaled)
    links.new(total.outputs[0], out.inputs["Shader"])
    return group


def _principled_specular(nodes, n, roughness):
    """Principled BSDF with a black base and single-scatter GGX: its specular
    layer alone, dielectric Fresnel of IOR n (Blender 4.2-4.5)."""
    node = nodes.new("ShaderNodeBsdfPrincipled")
    node.distribution = "GGX"
    node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    node.inputs["IOR"].default_value = n
    node.inputs["Roughness"].default_value = roughness
    return node


def _metallic(nodes, n, roughness):
    """Metallic BSDF, Beckmann, physical conductor of IOR n without extinction:
    the exact dielectric Fresnel microfacet lobe (Blender 5.0)."""
    node = nodes.new("ShaderNodeBsdfMetallic")
    node.distribution = "BECKMANN"
    node.fresnel_type = "PHYSICAL_CONDUCTOR"
    node.inputs["IOR"].default_value = (n, n, n)
    node.inputs["Extinction"].default_value = (0.0, 0.0, 0.0)
    node.inputs["Roughness"].default_value = roughness
    return node


def _closure_node(nodes, closure):
    if closure.kind == "lambert":
        node = nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Roughness"].default_value = 0.0
        return node
    node = nodes.new("ShaderNodeBsdfToon")
    node.component = "DIFFUSE" if closure.kind == "diffuse_toon" else "GLOSSY"
    node.inputs["Size"].default_value = closure.size
    node.inputs["Smooth"].default_value = closure.smooth
    return node


def _add(nodes, links, a, b):
    add = nodes.new("ShaderNodeAddShader")
    links.new(a.outputs[0], add.inputs[0])
    links.new(b.outputs[0], add.inputs[1])
    return add


def group_name(material, target):
    """The node group of a material's paint for a render engine."""
    return f"{GROUP_PREFIX} {material.name}" + ("" if target == "CYCLES" else f" {target.title()}")


def _node_name(target):
    return GROUP_PREFIX if target == "CYCLES" else f"{GROUP_PREFIX} {target.title()}"


def group_of(material, target="CYCLES"):
    """The material's Paint LUT group node for a render engine (None when it has none)."""
    tree = material.node_tree
    if tree is None:
        return None
    name = _node_name(target)
    return next((nd for nd in tree.nodes if nd.type == "GROUP" and nd.name == name and nd.node_tree), None)


def wire(material, groups):
    """Use the groups ({target: node group}) as the material's surface: a
    group node into a Material Output per render engine ('CYCLES', 'EEVEE').
    An existing output for all engines becomes Cycles' output."""
    if material.node_tree is None:  # Blender 4.x: a new material has no node tree yet
        material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    outputs = [nd for nd in nodes if nd.type == "OUTPUT_MATERIAL"]
    for nd in outputs:
        if nd.target == "ALL":
            nd.target = "CYCLES"
    for row, (target, group) in enumerate(groups.items()):
        node = group_of(material, target) or next((nd for nd in nodes if nd.name == _node_name(target)), None)
        if node is None:
            node = nodes.new("ShaderNodeGroup")
            node.name = node.label = _node_name(target)
        node.node_tree = group
        node.location = (0.0, -200.0 * row)
        output = next((nd for nd in outputs if nd.target == target), None)
        if output is None:
            output = nodes.new("ShaderNodeOutputMaterial")
            output.target = target
            outputs.append(output)
        output.location = (300.0, -200.0 * row)
        output.is_active_output = True
        links.new(node.outputs["Shader"], output.inputs["Surface"])
