"""Shared fixtures: the Blender add-on registered once per module, a fresh
empty Blender file per test, and a folder for LUTs passed to the add-on as a
parameter (``directory=``), never by patching the add-on.

Render tests (Cycles and EEVEE oracles) carry the ``render`` marker, so
``pytest -m "not render"`` is a quick loop.  Modules that need Blender import
``bpy`` with ``pytest.importorskip``; nothing here imports it unless a
Blender fixture is used."""

from __future__ import annotations

import pytest


def pytest_configure(config):
    config.addinivalue_line("markers", "render: renders with Cycles or EEVEE (slow); deselect with -m 'not render'")


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
