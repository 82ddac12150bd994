"""A Principled BSDF fallback on every paint material, for exporters.

glTF's and USD's exporters read only a Principled BSDF: the glTF exporter
(io_scene_gltf2, ``search_node_tree.get_node_socket``) takes the first
Principled BSDF node linked to the Material Output whose ``is_active_output``
is set, whatever that output's target, and a node tree has one active
Material Output (setting the flag clears it on the others); Blender's
renderers take, per engine, an output targeted at that engine, active or
not, before one for all engines (``ntreeShaderOutputNode``).  So the
fallback is a Principled BSDF, with the paint's fitted parameters
(``lut.render.principled.fit_principled``), into the active Material Output,
targeted at all engines: exporters see it, and Cycles and EEVEE keep
rendering the paint's groups from their own outputs (tested by renders).
Before a material's first bake (no engine outputs yet) the fallback is also
what renders: a fair preview."""

from __future__ import annotations

import json

from . import nodes
from ._lut import principled

#: Names of the fallback's nodes in a material's node tree.
NODE = "Paint LUT Principled"
OUTPUT = nodes.EXPORT_OUTPUT

#: Custom property holding the fallback's parameters and fit error (JSON).
PROPERTY = "paint_lut_principled"


def _node_tree(material):
    if material.node_tree is None:  # Blender 4.x: a new material has no node tree yet
        material.use_nodes = True
    return material.node_tree


def _linked(node) -> bool:
    return any(socket.is_linked for socket in (*node.inputs, *node.outputs))


def _values(node) -> list:
    return [
        tuple(s.default_value) if hasattr(s.default_value, "__len__") else s.default_value
        for s in node.inputs
        if hasattr(s, "default_value")
    ]


def _pristine_principled(tree, fallback) -> list:
    """The tree's Principled BSDFs but ``fallback`` as Blender makes them: no
    link in or out and every input at a new node's default (the new node to
    compare with is made once, and only where there is a node to compare)."""
    others = [nd for nd in tree.nodes if nd.type == "BSDF_PRINCIPLED" and nd != fallback and not _linked(nd)]
    if not others:
        return []
    reference = tree.nodes.new("ShaderNodeBsdfPrincipled")
    try:
        default = (reference.distribution, _values(reference))
    finally:
        tree.nodes.remove(reference)
    return [nd for nd in others if (nd.distribution, _values(nd)) == default]


def add_principled_fallback(material, params: principled.PrincipledParams, error: float | None = None):
    """Give ``material`` a Principled BSDF with ``params`` into an active
    Material Output for all engines (created, or updated in place when the
    material has them), leaving the engine-specific outputs active.  Records
    the parameters (and ``error``, the fit's fidelity measure) in the
    material's ``paint_lut_principled`` property.  Returns the BSDF node."""
    if not isinstance(params, principled.PrincipledParams):
        raise TypeError(f"params must be a lut.render.principled.PrincipledParams, got {type(params).__name__}")
    tree = _node_tree(material)
    nodes, links = tree.nodes, tree.links
    bsdf = nodes.get(NODE)
    if bsdf is not None and bsdf.type != "BSDF_PRINCIPLED":
        bsdf = None
    # USD's exporter takes the tree's first Principled BSDF, linked or not,
    # and a new material (Blender 5) holds a default one that the paint's
    # wiring leaves unlinked: such a node (no link in or out, every input at
    # its default) is taken over as the fallback when there is none yet, and
    # removed when there is, so that the exporter finds the fallback.  A
    # Principled BSDF an artist has edited is left alone.
    inert = _pristine_principled(tree, bsdf)
    if bsdf is None and inert:
        bsdf = inert.pop(0)
        bsdf.name = bsdf.label = NODE
    for orphan in inert:
        nodes.remove(orphan)
    if bsdf is None:
        bsdf = nodes.new("ShaderNodeBsdfPrincipled")
        bsdf.name = bsdf.label = NODE
        bsdf.location = (0.0, 400.0)
    bsdf.distribution = "GGX"  # the single-scatter GGX lut.render.principled models
    for name, value in params.node_inputs().items():
        bsdf.inputs[name].default_value = value
    output = nodes.get(OUTPUT)
    if output is None or output.type != "OUTPUT_MATERIAL":
        output = nodes.new("ShaderNodeOutputMaterial")
        output.name = output.label = OUTPUT
        output.location = (400.0, 400.0)
    output.target = "ALL"  # a bake's wiring may have re-targeted it
    links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    # Blender keeps one active Material Output per tree (setting one clears
    # the others); engines ignore the flag where an output is targeted at
    # them, exporters follow it.
    output.is_active_output = True
    record = {**params.to_dict(), "error": error}
    material[PROPERTY] = json.dumps(record)
    return bsdf


def fallback_params(material):
    """The recorded fallback of a material: (PrincipledParams, error), or
    None when it has none."""
    text = material.get(PROPERTY)
    if not text:
        return None
    record = json.loads(text)
    error = record.pop("error", None)
    return principled.PrincipledParams(**record), error


def update_fallback(material, paint):
    """Fit the Principled fallback to a material's paint (``paint``: a
    lut.Paint, ``api.paint_of(material)`` for its own settings) and add it:
    call after each bake.  Returns (PrincipledParams, its fidelity measure)."""
    try:
        params, error = principled.fit_principled(paint)
    except ValueError:
        # Nothing off the mirror to fit (a smooth paint whose only term is its
        # mirror, e.g. glossy black): a black base under the dielectric
        # specular layer is that mirror exactly.
        n = min(max(float(paint.index_at(589.3)), 1.0001), 4.0)
        params, error = principled.PrincipledParams(base_color=0.0, roughness=0.0, ior=n), 0.0
    add_principled_fallback(material, params, error)
    return params, error


def recolour_fallback(material, table, amplitudes):
    """After a colour edit: the material's fallback (if it has one) with its
    base colour solved again for the new colours (``principled.recolour``:
    the shape parameters are those fitted at the last bake).  ``table``: the
    type's loaded LUT; ``amplitudes``: the colours' (3 × 3) amplitudes."""
    recorded = fallback_params(material)
    if recorded is None:
        return None
    params, error = principled.recolour(recorded[0], table, amplitudes)
    add_principled_fallback(material, params, error)
    return params, error
