"""Node groups that render a paint type: closures weighted per view angle,
coloured by the group's inputs.

A paint's BRDF is Σ_c a_c·B_c (``lut.lutfiles.baking``): angular components of the
paint type scaled by colour amplitudes.  The group of a type and render
target (``build_group``) takes the colours as inputs,

* ``Pigment Color``            ρ (scene-linear RGB), turned into the diffuse
  amplitude k(ρ) = ρ(1 - r̄)/(1 - ρ r̄) in nodes (paper Eq. 27),
* ``Single Scattering Color``  the single-scatter albedo,
* ``Surface Reflection``       the facet weight,

reads the closure weights w_kc(θv) from the fit's Non-Color EXR
(``lut.render.fitting.write_fit``) at u = cos θv (Geometry Incoming · Normal), and
gives closure k the colour Σ_c a_c·w_kc.  Any colour source (an Image
Texture, an Attribute, Object Info › Random) connected to an input renders
the paint of that colour per pixel, and a colour edit is an input edit:
no bake.  Grey lobes (no colour input: Metallic, Principled) are scaled by
a Mix Shader factor, facet weight × w; a smooth interface's mirror is a
Metallic BSDF of roughness 0 (the exact dielectric Fresnel mirror in Blender
5; a Principled BSDF with a black base before) scaled by the facet weight.

Every material of one paint type shares its groups; a material gets one
group node per render engine, each into a Material Output targeted at it."""

from __future__ import annotations

import pathlib

import bpy

from . import osl
from ._lut import closures, fitting, lutfile

GROUP_PREFIX = "Paint LUT"
#: The Material Output of the Principled fallback for exporters (addon.export):
#: targeted at all engines and kept so.
EXPORT_OUTPUT = "Paint LUT Export Output"
INPUTS = ("Pigment Color", "Single Scattering Color", "Surface Reflection")

#: The Metallic BSDF's physical conductor Fresnel is the exact dielectric
#: Fresnel for extinction 0 from Blender 5.0 on; 4.3-4.5 use an approximate
#: conductor Fresnel (1.29-1.50x off for k = 0) and 4.2 has no Metallic BSDF.
#: There the facet lobes are Principled BSDFs with a black base (exact
#: dielectric Fresnel, GGX: lut.render.closures' "ggx" kind, fitted as such), and
#: the mirror is a Principled BSDF of roughness 0.  The default of every
#: ``exact_metallic`` parameter in the add-on.
EXACT_METALLIC = bpy.app.version >= (5, 0, 0)

#: Column x positions of the group's layout and the vertical spacing of its rows.
COLUMNS = {
    "input": (-1300.0, 0.0),
    "view": (-1000.0, 0.0),
    "colour": (-1000.0, -600.0),
    "weights": (-650.0, 0.0),
    "mix": (-250.0, 0.0),
    "closures": (150.0, 0.0),
    "sum": (550.0, 0.0),
}
GAP = 30.0


def exact_metallic_default(exact_metallic=None) -> bool:
    return EXACT_METALLIC if exact_metallic is None else bool(exact_metallic)


def _image(path):
    """The weights image, read as data (Non-Color), referenced relative to
    the .blend file when it is saved so a render farm finds it."""
    image = bpy.data.images.load(str(path), check_existing=True)
    image.reload()
    image.colorspace_settings.name = "Non-Color"
    if bpy.data.filepath:
        try:
            image.filepath = bpy.path.relpath(str(path))
        except ValueError:  # another drive (Windows): keep it absolute
            pass
    return image


def group_name(fit: fitting.Fit) -> str:
    """A readable, unique name for a paint type's group: its type and the
    start of its LUT key, with the render target."""
    t = fit.type
    if float(t.get("slope", 0)) > 0:
        surface = f"{t['distribution']} {float(t['slope']):g}"
    else:
        surface = "smooth"
    engine = "" if fit.target == "CYCLES" else f" {fit.target.title()}"
    engine += " OSL" if fit.osl else ""  # Cycles' OSL variant: a group of its own beside the SVM one
    return f"{GROUP_PREFIX} n{float(fit.n):g} {surface} g{float(t.get('g', 0)):g} {fit.lut_key[:8]}{engine}"


def _fit_id(fit: fitting.Fit, weights_path) -> str:
    """What identifies a group's content: its LUT, and the fit (header and
    weights file)."""
    content = lutfile.cache_key({"fit": fit.header(), "file": bpy.path.basename(str(weights_path))})
    return f"{fit.lut_key}:{fit.target}:{int(fit.exact_metallic)}:{content[:16]}"


class _Layout:
    """Places nodes in labelled frames, column by column."""

    def __init__(self, tree):
        self.tree = tree
        self.frames = {}
        self.rows = {}

    def frame(self, column, label):
        frame = self.frames.get(column)
        if frame is None:
            frame = self.tree.nodes.new("NodeFrame")
            frame.label = label
            frame.name = f"{label} frame"
            self.frames[column] = frame
        return frame

    def place(self, node, column, label, step=None):
        """Put ``node`` below the previous one of ``column``, in that column's frame."""
        x, y0 = COLUMNS[column]
        top = self.rows.get(column, -y0)
        node.parent = self.frame(column, label)
        node.location = (x, -top)
        self.rows[column] = top + estimated_height(node) + GAP
        return node


def estimated_height(node) -> float:
    """A generous estimate of a node's drawn height (Blender computes the real
    one only when an editor draws it): header, one line per shown socket,
    property rows and an image texture's image block."""
    sockets = sum(1 for s in node.inputs if s.enabled and not s.hide)
    sockets += sum(1 for s in node.outputs if s.enabled and not s.hide)
    extra = {"TEX_IMAGE": 180.0, "TEX_ENVIRONMENT": 180.0}.get(node.type, 0.0)
    props = 2 if node.type in ("BSDF_TOON", "BSDF_METALLIC", "BSDF_PRINCIPLED", "BSDF_GLOSSY", "BSDF_SHEEN") else 0
    props += 1 if node.type in ("MATH", "VECTOR_MATH") else 0
    return 40.0 + 24.0 * (sockets + props) + extra


def build_group(fit: fitting.Fit, weights_path, exact_metallic=None):
    """The shader node group rendering a paint type's fit (reused when a
    group of the same fit exists)."""
    name = group_name(fit)
    fit_id = _fit_id(fit, weights_path)
    old = bpy.data.node_groups.get(name)
    if (
        old is not None
        and old.get("paint_lut_fit") == fit_id
        and group_weights_path(old) == pathlib.Path(weights_path).resolve()
    ):
        return old
    if old is not None:
        old.name = f"{name} (old)"  # materials that use it keep it until rewired
    group = bpy.data.node_groups.new(name, "ShaderNodeTree")
    try:
        _fill_group(group, fit, weights_path, exact_metallic)
    except Exception:  # e.g. no OSL compiler for the variant's Script node: leave no half-built group
        images = {nd.image for nd in group.nodes if nd.type == "TEX_IMAGE" and nd.image}
        bpy.data.node_groups.remove(group)
        for image in images:
            if image.users == 0:  # loaded for this group alone
                bpy.data.images.remove(image)
        if old is not None:
            old.name = name
        raise
    group["paint_lut_fit"] = fit_id  # only a whole group is found again by its fit
    return group


def _fill_group(group, fit: fitting.Fit, weights_path, exact_metallic):
    """Build ``build_group``'s nodes into the new, empty ``group``."""
    if fit.target == "EEVEE":
        group["paint_lut_eevee_mode"] = fit.eevee_mode
    if hasattr(group, "description"):
        group.description = (
            "Paint LUT: a paint type (Germer's paint models) rendered as per-view weighted closures. "
            "Pigment Color is the diffuse pigment reflectance rho, Single Scattering Color the single "
            "scattering albedo, Surface Reflection the facet weight: connect textures to any of them."
        )
    _interface(group)
    tree, links = group, group.links
    lay = _Layout(tree)
    inputs = lay.place(tree.nodes.new("NodeGroupInput"), "input", "Inputs")
    u = _view_lookup(tree, links, lay, len(fit.cos_view))
    amps = _amplitudes(tree, links, lay, inputs, fit.internal_reflectance)
    image = _image(weights_path)
    rows = fitting.texels(fit.closures, fit.rows, fit.weights.shape[3])
    textures, ramps = {}, {}
    for r, slots in enumerate(rows):
        coord = lay.place(tree.nodes.new("ShaderNodeCombineXYZ"), "weights", "Weights per view")
        links.new(u, coord.inputs["X"])
        coord.inputs["Y"].default_value = (r + 0.5) / len(rows)
        live = [slot for slot in slots if slot is not None]
        coord.label = ", ".join(f"{fit.closures[k].kind} {fitting.COMPONENTS[c]}" for k, c in dict.fromkeys(live))
        tex = lay.place(tree.nodes.new("ShaderNodeTexImage"), "weights", "Weights per view")
        tex.image = image
        # Closest: the texture's columns are dense (fitting.TEXTURE_VIEWS);
        # Linear would let EEVEE's mipmaps blend the rows of other closures.
        tex.interpolation = "Closest"
        tex.extension = "EXTEND"
        links.new(coord.outputs[0], tex.inputs["Vector"])
        first = live[0]
        if fit.closures[first[0]].osl:  # three knots of an OSL ramp, in R, G, B
            ramps[first] = tex.outputs["Color"]
        elif all(slot == first for slot in slots):  # one row, a weight per channel
            textures[first] = tex.outputs["Color"]
        else:  # three rows, one per channel
            split = lay.place(tree.nodes.new("ShaderNodeSeparateColor"), "weights", "Weights per view")
            links.new(tex.outputs["Color"], split.inputs["Color"])
            for channel, slot in enumerate(slots):
                if slot is not None:
                    textures[slot] = split.outputs[channel]
    total = None
    for k, closure in enumerate(fit.closures):
        rows_k = [(c, textures[(k, c)]) for c in range(len(fitting.COMPONENTS)) if (k, c) in textures]
        if not rows_k:
            continue
        shader = NODE_BUILDERS[closure.kind](tree, links, lay, closure, rows_k, amps, exact_metallic)
        total = shader if total is None else _add(tree, links, lay, total, shader)
    if ramps:
        shader = _osl_ramps(tree, links, lay, fit, ramps, amps)
        total = shader if total is None else _add(tree, links, lay, total, shader)
    if fit.mirror:
        make = _metallic_node if exact_metallic_default(exact_metallic) else _principled_node
        mirror = lay.place(make(tree, fit.n, 0.0), "closures", "Closures")
        mirror.label = "Mirror (smooth interface)"
        mixed = _mix(tree, links, lay, amps["facet"], mirror.outputs[0])
        total = mixed if total is None else _add(tree, links, lay, total, mixed)
    out = tree.nodes.new("NodeGroupOutput")
    out.location = (COLUMNS["sum"][0] + 350.0, 0.0)
    if total is None:  # nothing to render (cannot happen for a fitted type, kept safe)
        total = tree.nodes.new("ShaderNodeBsdfTransparent").outputs[0]
    links.new(total, out.inputs["Shader"])


def group_weights_path(group):
    """The absolute path of the weights image a paint group reads (None
    when it has none)."""
    image = next((nd.image for nd in group.nodes if nd.type == "TEX_IMAGE" and nd.image), None)
    if image is None:
        return None
    return pathlib.Path(bpy.path.abspath(image.filepath, library=image.library)).resolve()


def _interface(group):
    sockets = (
        ("Pigment Color", "NodeSocketColor", (0.8, 0.8, 0.8, 1.0), "Diffuse pigment reflectance rho (scene-linear)"),
        ("Single Scattering Color", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0), "Single scattering albedo"),
        ("Surface Reflection", "NodeSocketFloat", 1.0, "Weight of the reflection by the surface itself, 0 to 1"),
    )
    for name, kind, default, description in sockets:
        socket = group.interface.new_socket(name=name, in_out="INPUT", socket_type=kind)
        socket.default_value = default
        socket.description = description
        if kind == "NodeSocketFloat":
            socket.min_value, socket.max_value = 0.0, 1.0
    group.interface.new_socket(name="Shader", in_out="OUTPUT", socket_type="NodeSocketShader")


def _view_lookup(tree, links, lay, views):
    """u = cos θv mapped onto texel centres: column j at u = (j + 0.5)/M
    holds cos θv = j/(M - 1), so a Closest lookup reads the column nearest
    to cos θv."""
    geometry = lay.place(tree.nodes.new("ShaderNodeNewGeometry"), "view", "View angle")
    dot = lay.place(tree.nodes.new("ShaderNodeVectorMath"), "view", "View angle")
    dot.operation = "DOT_PRODUCT"
    dot.label = "cos view"
    links.new(geometry.outputs["Incoming"], dot.inputs[0])
    links.new(geometry.outputs["Normal"], dot.inputs[1])
    to_u = lay.place(tree.nodes.new("ShaderNodeMath"), "view", "View angle")
    to_u.operation = "MULTIPLY_ADD"
    to_u.use_clamp = True
    to_u.label = "texture u"
    links.new(dot.outputs["Value"], to_u.inputs[0])
    to_u.inputs[1].default_value, to_u.inputs[2].default_value = fitting.texture_u(views)
    return to_u.outputs[0]


def _amplitudes(tree, links, lay, inputs, rbar):
    """The components' amplitudes from the inputs: facet (a value), single
    (a colour) and k(ρ) = ρ(1 - r̄)/(1 - ρ r̄) (a colour)."""
    num = lay.place(tree.nodes.new("ShaderNodeVectorMath"), "colour", "Pigment to diffuse amplitude")
    num.operation = "SCALE"
    num.label = "rho (1 - rbar)"
    links.new(inputs.outputs["Pigment Color"], num.inputs[0])
    num.inputs["Scale"].default_value = 1.0 - rbar
    den = lay.place(tree.nodes.new("ShaderNodeVectorMath"), "colour", "Pigment to diffuse amplitude")
    den.operation = "MULTIPLY_ADD"
    den.label = "1 - rho rbar"
    links.new(inputs.outputs["Pigment Color"], den.inputs[0])
    den.inputs[1].default_value = (-rbar, -rbar, -rbar)
    den.inputs[2].default_value = (1.0, 1.0, 1.0)
    k = lay.place(tree.nodes.new("ShaderNodeVectorMath"), "colour", "Pigment to diffuse amplitude")
    k.operation = "DIVIDE"
    k.label = "k(rho)"
    links.new(num.outputs[0], k.inputs[0])
    links.new(den.outputs[0], k.inputs[1])
    return {
        "facet": inputs.outputs["Surface Reflection"],
        "single": inputs.outputs["Single Scattering Color"],
        "diffuse": k.outputs[0],
    }


def _colour(tree, links, lay, rows_k, amps):
    """Σ_c a_c·w_kc: the colour of a coloured closure."""
    total = None
    for c, weight in rows_k:
        name = fitting.COMPONENTS[c]
        term = lay.place(tree.nodes.new("ShaderNodeVectorMath"), "mix", "Closure colours")
        term.operation = "SCALE" if name == "facet" else "MULTIPLY"
        term.label = f"{name} x weight"
        links.new(weight, term.inputs[0])
        links.new(amps[name], term.inputs["Scale"] if name == "facet" else term.inputs[1])
        if total is None:
            total = term.outputs[0]
        else:
            add = lay.place(tree.nodes.new("ShaderNodeVectorMath"), "mix", "Closure colours")
            add.operation = "ADD"
            links.new(total, add.inputs[0])
            links.new(term.outputs[0], add.inputs[1])
            total = add.outputs[0]
    return total


def _grey_weight(tree, links, lay, rows_k, amps):
    """Facet weight × w: a grey closure's Mix Shader factor."""
    (c, weight), *_ = rows_k
    fac = lay.place(tree.nodes.new("ShaderNodeMath"), "mix", "Closure colours")
    fac.operation = "MULTIPLY"
    fac.use_clamp = True
    fac.label = "facet x weight"
    links.new(weight, fac.inputs[0])
    links.new(amps[fitting.COMPONENTS[c]], fac.inputs[1])
    return fac.outputs[0]


def _mix(tree, links, lay, factor, shader):
    """factor · shader (a Mix Shader with nothing in its first slot)."""
    mix = lay.place(tree.nodes.new("ShaderNodeMixShader"), "sum", "Sum of closures")
    links.new(factor, mix.inputs["Fac"])
    links.new(shader, mix.inputs[2])
    return mix.outputs[0]


def _add(tree, links, lay, a, b):
    add = lay.place(tree.nodes.new("ShaderNodeAddShader"), "sum", "Sum of closures")
    links.new(a, add.inputs[0])
    links.new(b, add.inputs[1])
    return add.outputs[0]


def _coloured(node_type, setup):
    def build(tree, links, lay, closure, rows_k, amps, exact_metallic):
        node = lay.place(tree.nodes.new(node_type), "closures", "Closures")
        setup(node, closure)
        node.label = closure.kind.replace("_", " ")
        links.new(_colour(tree, links, lay, rows_k, amps), node.inputs["Color"])
        return node.outputs[0]

    return build


def _setup_lambert(node, closure):
    node.inputs["Roughness"].default_value = 0.0


def _setup_toon(node, closure):
    node.component = "DIFFUSE" if closure.kind == "diffuse_toon" else "GLOSSY"
    node.inputs["Size"].default_value = closure.size
    node.inputs["Smooth"].default_value = closure.smooth


def _retro(tree, links, lay, closure, rows_k, amps, exact_metallic):
    """A Diffuse Toon whose normal is the view direction: a retro lobe."""
    node = lay.place(tree.nodes.new("ShaderNodeBsdfToon"), "closures", "Closures")
    _setup_toon(node, closure)
    node.component = "DIFFUSE"
    node.label = "retro toon"
    incoming = lay.place(tree.nodes.new("ShaderNodeNewGeometry"), "mix", "Closure colours")
    links.new(incoming.outputs["Incoming"], node.inputs["Normal"])
    links.new(_colour(tree, links, lay, rows_k, amps), node.inputs["Color"])
    return node.outputs[0]


def _retro_glossy(tree, links, lay, closure, rows_k, amps, exact_metallic):
    """A GGX Glossy BSDF whose normal is the view direction: a retro lobe
    that EEVEE draws as a reflection closure."""
    node = lay.place(tree.nodes.new("ShaderNodeBsdfGlossy"), "closures", "Closures")
    node.distribution = "GGX"
    node.inputs["Roughness"].default_value = closure.roughness
    node.label = f"retro lobe {closure.roughness:.3g}"
    incoming = lay.place(tree.nodes.new("ShaderNodeNewGeometry"), "mix", "Closure colours")
    links.new(incoming.outputs["Incoming"], node.inputs["Normal"])
    links.new(_colour(tree, links, lay, rows_k, amps), node.inputs["Color"])
    return node.outputs[0]


def _setup_glossy(node, closure):
    node.distribution = "BECKMANN"
    node.inputs["Roughness"].default_value = closure.roughness


def _setup_sheen(node, closure):
    node.distribution = "ASHIKHMIN"
    node.inputs["Roughness"].default_value = closure.roughness


def _metallic_node(tree, n, roughness):
    """Metallic BSDF, Beckmann, physical conductor of IOR n without extinction:
    the exact dielectric Fresnel microfacet lobe (Blender 5.0)."""
    node = tree.nodes.new("ShaderNodeBsdfMetallic")
    node.distribution = "BECKMANN"
    node.fresnel_type = "PHYSICAL_CONDUCTOR"
    node.inputs["IOR"].default_value = (n, n, n)
    node.inputs["Extinction"].default_value = (0.0, 0.0, 0.0)
    node.inputs["Roughness"].default_value = roughness
    return node


def _principled_node(tree, n, roughness):
    """Principled BSDF with a black base and single-scatter GGX: its specular
    layer alone, dielectric Fresnel of IOR n (Blender 4.2-4.5)."""
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.distribution = "GGX"
    node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    node.inputs["IOR"].default_value = n
    node.inputs["Roughness"].default_value = roughness
    return node


def _grey(make):
    def build(tree, links, lay, closure, rows_k, amps, exact_metallic):
        node = lay.place(make(tree, closure.ior, closure.roughness), "closures", "Closures")
        node.label = f"facet lobe {closure.roughness:.3g}"
        return _mix(tree, links, lay, _grey_weight(tree, links, lay, rows_k, amps), node.outputs[0])

    return build


def _oren_nayar(tree, links, lay, closure, rows_k, amps, exact_metallic):
    """Oren-Nayar per channel: a Diffuse BSDF of unit colour in one channel,
    scaled by that channel of the closure colour (a Mix Shader factor), so
    the albedo-dependent multiple scattering term of Cycles' Oren-Nayar
    stays that of albedo 1, as fitted."""
    colour = _colour(tree, links, lay, rows_k, amps)
    split = lay.place(tree.nodes.new("ShaderNodeSeparateXYZ"), "mix", "Closure colours")
    links.new(colour, split.inputs[0])
    total = None
    for ch, axis in enumerate("XYZ"):
        node = lay.place(tree.nodes.new("ShaderNodeBsdfDiffuse"), "closures", "Closures")
        node.label = f"oren nayar {'RGB'[ch]}"
        node.inputs["Roughness"].default_value = closure.roughness
        node.inputs["Color"].default_value = tuple(1.0 if i == ch else 0.0 for i in range(3)) + (1.0,)
        mixed = _mix(tree, links, lay, split.outputs[axis], node.outputs[0])
        total = mixed if total is None else _add(tree, links, lay, total, mixed)
    return total


def _osl_ramps(tree, links, lay, fit, ramps, amps):
    """The OSL variant's ramps: one Script node (``osl.ramps_node``) fed the
    colour amplitudes and, per ramp, component and trio of knots, the
    texel that holds their weights ({(first knot's closure index,
    component): texture colour})."""
    node = lay.place(osl.ramps_node(tree), "closures", "Closures")
    for name, socket in osl.AMPLITUDES.items():
        links.new(amps[name], node.inputs[socket])
    phong = []
    for closure in fit.closures:
        if closure.kind == "phong_ramp" and closure.exponent not in phong:
            phong.append(closure.exponent)
    letters = [f for f in osl.FAMILIES if f not in osl.KIND_FAMILY.values()]
    kinds = {c.kind for c in fit.closures if c.osl}
    if len(phong) > len(letters) or kinds - set(osl.KIND_FAMILY) - {"phong_ramp"}:
        raise ValueError(f"the OSL ramps shader draws a diffuse, a retro and two Phong ramps, not {sorted(kinds)}")
    phong_letter = dict(zip(phong, letters, strict=False))
    for (k, c), colour in ramps.items():
        closure = fit.closures[k]
        family = phong_letter[closure.exponent] if closure.kind == "phong_ramp" else osl.KIND_FAMILY[closure.kind]
        links.new(colour, node.inputs[osl.weight_input(family, fitting.COMPONENTS[c], closure.knot // 3)])
        if family in osl.EXPONENTS:
            node.inputs[osl.EXPONENTS[family]].default_value = closure.exponent
    return node.outputs[osl.OUTPUT]


#: How each closure kind of ``lut.render.closures.CLOSURE_KINDS`` is built
#: (the OSL ramps' knots all by one Script node, ``_osl_ramps``).
NODE_BUILDERS = {
    "lambert": _coloured("ShaderNodeBsdfDiffuse", _setup_lambert),
    "diffuse_toon": _coloured("ShaderNodeBsdfToon", _setup_toon),
    "glossy_toon": _coloured("ShaderNodeBsdfToon", _setup_toon),
    "retro_toon": _retro,
    "glossy": _coloured("ShaderNodeBsdfGlossy", _setup_glossy),
    "sheen": _coloured("ShaderNodeBsdfSheen", _setup_sheen),
    "metallic": _grey(_metallic_node),
    "ggx": _grey(_principled_node),
    "oren_nayar": _oren_nayar,
    "retro_glossy": _retro_glossy,
}
assert set(NODE_BUILDERS) == {kind for kind, spec in closures.CLOSURE_KINDS.items() if not spec.osl}


def build_seen_group(fit: fitting.Fit, albedo: float):
    """A small group for colours picked as seen: ``Color (as seen)`` (the
    diffuse colour head-on, k(ρ)·a_D) in, the ``Pigment Color`` ρ that gives
    it out (k = min(colour/a_D, 1), ρ = k/(1 - r̄ + k r̄)).  Put it between a
    texture painted in seen colours and the paint group's Pigment Color."""
    name = f"{GROUP_PREFIX} As Seen {fit.lut_key[:8]}"
    group = bpy.data.node_groups.get(name)
    if group is not None and group.get("paint_lut_albedo") == round(albedo, 9):
        return group
    if group is None:
        group = bpy.data.node_groups.new(name, "ShaderNodeTree")
    group.nodes.clear()
    group.interface.clear()
    group["paint_lut_albedo"] = round(albedo, 9)
    if hasattr(group, "description"):
        group.description = "Paint LUT: the pigment colour rho that shows a given diffuse colour head-on"
    socket = group.interface.new_socket(name="Color (as seen)", in_out="INPUT", socket_type="NodeSocketColor")
    socket.default_value = (0.5, 0.5, 0.5, 1.0)
    group.interface.new_socket(name="Pigment Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    nodes_, links = group.nodes, group.links
    inp, out = nodes_.new("NodeGroupInput"), nodes_.new("NodeGroupOutput")
    steps = []
    for op, label in (("SCALE", "k = colour / albedo"), ("MINIMUM", "k <= 1"), ("MULTIPLY_ADD", "k rbar + 1 - rbar"),
                      ("DIVIDE", "rho = k / (...)")):  # fmt: skip
        node = nodes_.new("ShaderNodeVectorMath")
        node.operation, node.label = op, label
        steps.append(node)
    scale, cap, den, div = steps
    links.new(inp.outputs[0], scale.inputs[0])
    scale.inputs["Scale"].default_value = 1.0 / albedo
    links.new(scale.outputs[0], cap.inputs[0])
    cap.inputs[1].default_value = (1.0, 1.0, 1.0)
    rbar = fit.internal_reflectance
    links.new(cap.outputs[0], den.inputs[0])
    den.inputs[1].default_value = (rbar, rbar, rbar)
    den.inputs[2].default_value = (1.0 - rbar,) * 3
    links.new(cap.outputs[0], div.inputs[0])
    links.new(den.outputs[0], div.inputs[1])
    links.new(div.outputs[0], out.inputs[0])
    for i, node in enumerate([inp, *steps, out]):
        node.location = (220.0 * i, 0.0)
    return group


def _node_name(target):
    return GROUP_PREFIX if target == "CYCLES" else f"{GROUP_PREFIX} {target.title()}"


def group_of(material, target="CYCLES"):
    """The material's Paint LUT group node for a render engine (None when it has none)."""
    tree = material.node_tree
    if tree is None:
        return None
    name = _node_name(target)
    return next((nd for nd in tree.nodes if nd.type == "GROUP" and nd.name == name and nd.node_tree), None)


def is_paint_group(group) -> bool:
    """Whether a node group is one of this version's paint groups (it has the colour inputs)."""
    names = {item.name for item in group.interface.items_tree if getattr(item, "in_out", "") == "INPUT"}
    return set(INPUTS) <= names and "paint_lut_fit" in group


def set_inputs(material, values: dict) -> None:
    """Set the colour inputs of the material's paint group nodes (unlinked
    ones: a linked input follows its texture)."""
    for target in closures.TARGETS:
        node = group_of(material, target)
        if node is None:
            continue
        for name, value in values.items():
            socket = node.inputs.get(name)
            if socket is None or socket.is_linked:
                continue
            socket.default_value = (*value, 1.0) if isinstance(value, tuple) else value


def wire(material, groups, values=None):
    """Use the groups ({target: node group}) as the material's surface: a
    group node into a Material Output per render engine ('CYCLES', 'EEVEE'),
    with the colour inputs ``values``.  An existing output for all engines
    becomes Cycles' output.  Links into the group nodes' inputs (textures)
    are kept."""
    if material.node_tree is None:  # Blender 4.x: a new material has no node tree yet
        material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    outputs = [nd for nd in nodes if nd.type == "OUTPUT_MATERIAL" and nd.name != EXPORT_OUTPUT]
    for nd in outputs:
        if nd.target == "ALL":
            nd.target = "CYCLES"
    for row, (target, group) in enumerate(groups.items()):
        node = group_of(material, target) or next((nd for nd in nodes if nd.name == _node_name(target)), None)
        kept = []
        if node is None:
            node = nodes.new("ShaderNodeGroup")
            node.name = node.label = _node_name(target)
            node.location = (0.0, -300.0 * row)
        else:
            kept = [(lk.from_socket, lk.to_socket.name) for lk in links if lk.to_node == node]
        node.node_tree = group
        node.width = 240.0
        for from_socket, name in kept:
            if name in node.inputs:
                links.new(from_socket, node.inputs[name])
        output = next((nd for nd in outputs if nd.target == target), None)
        if output is None:
            output = nodes.new("ShaderNodeOutputMaterial")
            output.target = target
            output.location = (400.0, -300.0 * row)
            outputs.append(output)
        output.is_active_output = True
        links.new(node.outputs["Shader"], output.inputs["Surface"])
    if values:
        set_inputs(material, values)
