"""Shared fixtures: the Blender add-on registered once per module, a fresh
empty Blender file per test, and a folder for LUTs passed to the add-on as a
parameter (``directory=``), never by patching the add-on.

Render tests (Cycles and EEVEE oracles) carry the ``render`` marker, so
``pytest -m "not render"`` is a quick loop.  Cycles renders also carry
``cycles``: they check the fits and node groups against Cycles' closures,
not a Blender version's EEVEE tables, so ``scripts/test.sh`` runs them under
one Blender only (Blender 5.2 LTS when it has it) and sets
``PAINT_LUT_CYCLES_ELSEWHERE`` for the other run, which skips them saying where
they ran.  EEVEE renders run under every Blender, each against its own
tables.  Modules that need Blender import
``bpy`` with ``pytest.importorskip``; nothing here imports it unless a
Blender fixture is used."""

from __future__ import annotations

import os

import pytest


def pytest_configure(config):
    config.addinivalue_line("markers", "render: renders with Cycles or EEVEE (slow); deselect with -m 'not render'")
    config.addinivalue_line(
        "markers", "cycles: a Cycles render; skipped where PAINT_LUT_CYCLES_ELSEWHERE names the Blender that runs it"
    )


def pytest_collection_modifyitems(config, items):
    """Skip the Cycles renders where another environment of scripts/test.sh runs them."""
    elsewhere = os.environ.get("PAINT_LUT_CYCLES_ELSEWHERE", "").strip()
    if not elsewhere:
        return
    skip = pytest.mark.skip(reason=f"Cycles renders run once per test.sh, under {elsewhere}")
    for item in items:
        if item.get_closest_marker("cycles") is not None:
            item.add_marker(skip)


@pytest.fixture(scope="module")
def addon_registered():
    """The add-on registered for the module's tests, unregistered after."""
    pytest.importorskip("bpy")
    import addon

    addon.register()
    yield addon
    addon.unregister()


@pytest.fixture
def fresh_file(addon_registered):
    """Blender reset to an empty file (factory settings), the add-on registered."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.data


@pytest.fixture
def lut_dir(tmp_path):
    """A folder for a test's LUTs and weights files."""
    path = tmp_path / "luts"
    path.mkdir()
    return path
