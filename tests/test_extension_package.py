"""The extension zip (scripts/build_extension.py): built and validated by
Blender's own builder, then installed into a clean Blender user directory
with no network, where a preset is baked and rendered by the shipped oracle
and the shipped batch command finds the saved file's bake current."""

import importlib.util
import os
import pathlib
import subprocess
import sys
import textwrap
import tomllib
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("build_extension", ROOT / "scripts" / "build_extension.py")
build_extension = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(build_extension)


@pytest.fixture(scope="module")
def package(tmp_path_factory):
    return build_extension.build(tmp_path_factory.mktemp("dist"))


def test_zip_holds_the_add_on_manifest_and_lut_wheel(package):
    with zipfile.ZipFile(package) as archive:
        names = set(archive.namelist())
        manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())
        wheel = manifest["wheels"][0].removeprefix("./")
        # The one permission says what is written, where, and why.
        assert ".blend" in manifest["permissions"]["files"] and "reuse" in manifest["permissions"]["files"]
        assert {
            "__init__.py",
            "api.py",
            "batch.py",
            "nodes.py",
            "properties.py",
            "scenes.py",
            "library.py",
            wheel,
        } <= names
        assert {"assets/paint_lut_library.blend", "assets/blender_assets.cats.txt"} <= names
        assert not any(name.startswith(("lut/", "tests/", "scripts/")) or "__pycache__" in name for name in names)
        with zipfile.ZipFile(archive.open(wheel)) as inner:
            files = set(inner.namelist())
    package = build_extension.PACKAGE
    assert {f"{package}/__init__.py", f"{package}/colour/data.py", f"{package}/models/rough.py"} <= files
    assert {f"{package}/{layer}/__init__.py" for layer in ("colour", "paint", "lutfiles", "render")} <= files
    assert f"{package}/render/principled.py" in files
    assert not any(f.startswith(("lut/", "addon/", "tests/")) for f in files)
    record = next(f for f in files if f.endswith(".dist-info/RECORD"))
    assert record.startswith("paint_lut-0.1.0.dist-info/")


def test_wheel_leaves_out_development_modules_and_still_imports(tmp_path):
    """No plots or benchmarks in the wheel, and what is left imports without
    them: the package, its CLI module (whose example command needs them) and
    everything the add-on uses."""
    wheel = build_extension.build_wheel(tmp_path)
    package = build_extension.PACKAGE
    with zipfile.ZipFile(wheel) as inner:
        files = set(inner.namelist())
        inner.extractall(tmp_path / "site")
    for module in build_extension.DEV_ONLY:
        assert f"{package}/{module}" not in files
    code = textwrap.dedent(
        f"""
        import importlib, sys
        sys.modules["matplotlib"] = None  # no matplotlib either
        for name in (
            "", ".__main__", ".render.principled", ".render.bake", ".render.fitting", ".lutfiles.format",
            ".lutfiles.exr", ".paint.schema", ".lutfiles.files", ".paint.presets", ".paint.gloss", ".render.eevee",
        ):
            importlib.import_module("{package}" + name)
        from {package} import __main__ as cli
        try:
            cli.main(["example", "--out", {str(tmp_path / "out")!r}])
        except SystemExit as exit:
            print("EXIT", exit.code)
        """
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(tmp_path / "site")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "EXIT error: the example command needs the repository's lut" in done.stdout


def test_wheel_is_reproducible(tmp_path):
    a = build_extension.build_wheel(tmp_path)
    first = a.read_bytes()
    a.unlink()
    assert build_extension.build_wheel(tmp_path).read_bytes() == first


def _validate(source):
    command = [*build_extension.builder(None), "validate", str(source)]
    return subprocess.run(command, capture_output=True, text=True)


def test_manifest_passes_blenders_validator(tmp_path):
    source = build_extension.stage(tmp_path)
    done = _validate(source)
    assert done.returncode == 0, done.stdout + done.stderr


def test_validator_rejects_a_bad_manifest(tmp_path):
    """The validator is really consulted: a malformed version fails it."""
    source = build_extension.stage(tmp_path)
    manifest = source / "blender_manifest.toml"
    manifest.write_text(manifest.read_text().replace('"4.2.0"', '"4.2"'))
    done = _validate(source)
    assert done.returncode != 0
    assert "blender_version_min" in done.stdout + done.stderr


def test_manifest_and_versions_agree():
    build_extension.check_versions()  # raises SystemExit on a mismatch


INSTALLED = textwrap.dedent(
    """
    import importlib, json, math, sys
    sys.path.insert(0, {foreign!r})  # another extension's top-level lut
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)  # first: it resets the preferences
    result = bpy.ops.extensions.package_install_files(
        filepath={zip!r}, repo="user_default", enable_on_install=True
    )
    assert result == {{"FINISHED"}}, result
    scenes = importlib.import_module("bl_ext.user_default.paint_lut.scenes")
    oracle = scenes.Oracle(reset=False)  # the shipped oracle, in the empty file
    import lut as foreign
    assert foreign.FOREIGN, "the foreign lut is first on sys.path"
    import paint_lut_core as lut
    api = importlib.import_module("bl_ext.user_default.paint_lut.api")
    seam = importlib.import_module("bl_ext.user_default.paint_lut._lut")
    print("SEAM_FROM", seam.lut.__file__)
    libraries = bpy.context.preferences.filepaths.asset_libraries
    print("ASSET_LIBRARY", *[lib.path for lib in libraries if lib.name == "Paint LUT"])
    print("API_LUT", api.lut.__name__)
    material = bpy.data.materials.new("paint")
    material.paint_lut.preset = "glossy_red"
    material.paint_lut.enabled = True
    bpy.ops.wm.save_as_mainfile(filepath={blend!r})
    api.bake_material(material)
    oracle.plane.data.materials.clear()
    oracle.plane.data.materials.append(material)
    rendered = oracle.brdf(0.5, 0.7, 1.2)
    model = lut.preset("glossy_red").brdf(0.5, 0.7, 1.2)
    print("LUT_FROM", lut.__file__)
    print("ADDON_FROM", api.__file__)
    print("LUT_PATH", material.paint_lut.lut_path)
    print("RENDERED", *rendered)
    print("MODEL", *model)
    bpy.ops.wm.save_mainfile()
    batch = importlib.import_module("bl_ext.user_default.paint_lut.batch")  # the shipped farm command
    code = batch.main([{blend!r}, "--report", {report!r}])
    print("BATCH", code, json.load(open({report!r}))[0]["materials"]["paint"]["status"])
    """
)


def test_installs_offline_into_a_clean_user_directory_and_renders(package, tmp_path):
    resources = tmp_path / "blender_user"
    foreign = tmp_path / "foreign"
    (foreign / "lut").mkdir(parents=True)
    (foreign / "lut" / "__init__.py").write_text("FOREIGN = True\n")
    code = INSTALLED.format(
        foreign=str(foreign), zip=str(package), blend=str(tmp_path / "scene.blend"), report=str(tmp_path / "bake.json")
    )
    env = {k: v for k, v in os.environ.items() if k not in {"PYTHONPATH", "BLENDER_USER_SCRIPTS"}}
    env.update(
        BLENDER_USER_RESOURCES=str(resources),
        no_proxy="*",
        http_proxy="http://0.0.0.0:9",
        https_proxy="http://0.0.0.0:9",
    )
    # Run outside the repository so that `lut` can only come from the extension's wheel.
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    out = dict(
        line.split(" ", 1) for line in done.stdout.splitlines() if line.split(" ", 1)[0].isupper() and " " in line
    )
    assert pathlib.Path(out["LUT_FROM"]).is_relative_to(resources)
    assert out["SEAM_FROM"] == out["LUT_FROM"]
    assert out["API_LUT"] == "paint_lut_core"
    # The bundled asset library is registered from where the extension was installed.
    installed = resources / "extensions" / "user_default" / "paint_lut"
    assert pathlib.Path(out["ASSET_LIBRARY"]) == installed / "assets"
    assert (installed / "assets" / "paint_lut_library.blend").is_file()
    assert pathlib.Path(out["ADDON_FROM"]).is_relative_to(resources / "extensions" / "user_default" / "paint_lut")
    assert out["LUT_PATH"].startswith("//paint_lut/")
    assert (tmp_path / out["LUT_PATH"][2:]).exists()
    assert out["BATCH"] == "0 cached"  # the file's material, baked above, found current
    rendered = [float(v) for v in out["RENDERED"].split()]
    model = [float(v) for v in out["MODEL"].split()]
    for r, m in zip(rendered, model, strict=True):
        assert abs(r - m) <= 0.05 * max(model), (rendered, model)


def test_a_working_copy_with_untracked_sources_is_refused(tmp_path):
    """An untracked module in lut/ would go into the wheel: the build names
    it and stops before writing anything."""
    stray = ROOT / "lut" / "zz_untracked_for_test.py"
    stray.write_text("X = 1\n")
    try:
        assert "lut/zz_untracked_for_test.py" in build_extension.untracked()
        with pytest.raises(SystemExit, match="untracked files would go into the extension: .*zz_untracked_for_test"):
            build_extension.build(tmp_path / "dist")
    finally:
        stray.unlink()
    assert not (tmp_path / "dist").exists()
    assert "lut/zz_untracked_for_test.py" not in build_extension.untracked()
