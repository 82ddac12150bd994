"""The paint's other render targets: EEVEE's own output (not an exact
oracle: measured, with a loose bound) and, for Blender 4.2-4.5, facet lobes
made of Principled BSDFs instead of Metallic ones (checked in Cycles)."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from addon.scenes import EEVEE, Oracle, paint_material, paints, relative_rms  # noqa: E402

pytestmark = pytest.mark.render


@pytest.fixture
def registered():
    import addon

    addon.register()
    yield
    addon.unregister()


def test_eevee_renders_its_own_fit(registered, tmp_path):
    oracle = Oracle(engine=EEVEE)
    try:
        oracle.radiance(0.3, 0.3, 1.0)
    except RuntimeError as exc:  # no GPU context (no EGL/Mesa) on this machine
        pytest.skip(f"EEVEE cannot render here: {exc}")
    paint = paints()["glossy white"]
    material, _ = paint_material(oracle, paint, tmp_path)
    grid = (np.radians([10, 45, 70]), np.radians([10, 50]), (0.8, 2.4))
    assert relative_rms(oracle, paint, grid) < 0.05  # 4.74% on the fidelity measure (its fit reports 3.39%)
    # The Cycles output is not what EEVEE drew: point EEVEE at it and the error grows.
    material.node_tree.get_output_node("EEVEE").is_active_output = False
    for node in material.node_tree.nodes:
        if node.type == "OUTPUT_MATERIAL":
            node.target = "ALL" if node.target == "CYCLES" else "CYCLES"
    assert relative_rms(oracle, paint, grid) > 0.08


def test_principled_facet_lobes_for_blender_4(registered, tmp_path):
    """Blender 4.2-4.5 get Principled (GGX, black base) facet lobes: exact
    Fresnel, GGX instead of Beckmann; the satin paint stays within 5%."""
    from addon import nodes

    oracle = Oracle()
    paint = paints()["satin"]
    material, _ = paint_material(oracle, paint, tmp_path, exact_metallic=False)
    group = nodes.group_of(material).node_tree
    assert any(nd.type == "BSDF_PRINCIPLED" for nd in group.nodes)
    assert not any(nd.type == "BSDF_METALLIC" for nd in group.nodes)
    assert relative_rms(oracle, paint) < 0.05
