"""lut is pure Python over numpy, OpenImageIO and colour-science: it never
imports bpy (dependencies point one way, addon -> lut)."""

import ast
import pathlib

LUT = pathlib.Path(__file__).resolve().parents[1] / "lut"


def test_lut_never_imports_bpy():
    for path in LUT.rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            assert not any(n == "bpy" or n.startswith("bpy.") for n in names), f"{path} imports bpy"
