"""Build the Blender extension zip: dist/paint_lut-<version>.zip.

    .venv/bin/python scripts/build_extension.py [--output-dir dist] [--blender PATH]

The zip holds the add-on (addon/*.py, relative imports) with the repository's
blender_manifest.toml, its bundled asset library (addon/assets/: the paint
materials' .blend and its catalogs), and the library as a wheel of its own
(wheels/paint_lut-<version>-py3-none-any.whl).  Blender installs bundled
wheels into the extensions' shared site-packages, where another extension's
top-level ``lut`` could clash with ours, so the wheel's package is the
repository's ``lut`` renamed ``paint_lut_core`` (its imports are relative);
the add-on imports it through addon/_lut.py.  The development-only modules
(``DEV_ONLY``: plots, benchmarks and the models' reference method) are left out.

The one wheel is pure Python and serves Linux, Windows and macOS alike: at run
time lut needs only numpy and OpenImageIO, which Blender 5.0 ships, and its
colour numbers are stored data (lut/colour/data.py), so neither
colour-science nor scipy (per-platform wheels) is bundled.

The zip is built and validated by Blender's own extension builder: ``blender
--command extension build`` when a Blender executable is given (or on PATH),
otherwise the same builder script (blender_ext.py) from the pip bpy module."""

from __future__ import annotations

import argparse
import base64
import hashlib
import importlib.util
import pathlib
import shutil
import subprocess
import sys
import tempfile
import tomllib
import zipfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: The library's package name inside the wheel (addon/_lut.py imports it).
PACKAGE = "paint_lut_core"

#: lut modules the wheel leaves out: matplotlib plots (figures, and examples,
#: which draws them) and benchmarks; the CLI's ``example`` command says so.
DEV_ONLY = ("bench.py", "examples.py", "figures.py", "models/reference.py")

#: The asset library's files (scripts/make_assets.py), packed under assets/.
ASSETS = ("paint_lut_library.blend", "blender_assets.cats.txt")

#: zip entries get this fixed time, so the same sources give the same wheel.
EPOCH = (1980, 1, 1, 0, 0, 0)


def project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def manifest() -> dict:
    return tomllib.loads((ROOT / "blender_manifest.toml").read_text())


def wheel_name() -> str:
    meta = project()
    return f"{meta['name'].replace('-', '_')}-{meta['version']}-py3-none-any.whl"


def check_versions() -> None:
    """The manifest, pyproject and lut.__version__ must agree, and the
    manifest must list the wheel this script writes."""
    import lut

    meta, man = project(), manifest()
    versions = {"pyproject.toml": meta["version"], "blender_manifest.toml": man["version"], "lut": lut.__version__}
    if len(set(versions.values())) != 1:
        raise SystemExit(f"error: versions differ: {versions}")
    if man.get("wheels") != [f"./wheels/{wheel_name()}"]:
        raise SystemExit(f"error: blender_manifest.toml must list wheels = ['./wheels/{wheel_name()}']")


def _add(archive: zipfile.ZipFile, name: str, data: bytes, record: list) -> None:
    info = zipfile.ZipInfo(name, EPOCH)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    archive.writestr(info, data)
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    record.append(f"{name},sha256={digest},{len(data)}")


def build_wheel(directory: pathlib.Path) -> pathlib.Path:
    """Write the pure-Python wheel of ``lut`` as ``PACKAGE`` (PEP 427),
    without ``DEV_ONLY``, into ``directory``."""
    meta = project()
    dist_info = f"{meta['name'].replace('-', '_')}-{meta['version']}.dist-info"
    path = directory / wheel_name()
    record: list[str] = []
    library = ROOT / "lut"
    sources = sorted(
        p
        for p in library.rglob("*.py")
        if "__pycache__" not in p.parts and p.relative_to(library).as_posix() not in DEV_ONLY
    )
    metadata = [
        "Metadata-Version: 2.1",
        f"Name: {meta['name']}",
        f"Version: {meta['version']}",
        f"Summary: {meta['description']}",
        f"License: {meta['license']['text']}",
        f"Requires-Python: {meta['requires-python']}",
        *(f"Requires-Dist: {dep}" for dep in meta["dependencies"]),
    ]
    wheel = ["Wheel-Version: 1.0", "Generator: paint-lut scripts/build_extension.py", "Root-Is-Purelib: true"]
    wheel.append("Tag: py3-none-any")
    with zipfile.ZipFile(path, "w") as archive:
        for source in sources:
            _add(archive, f"{PACKAGE}/{source.relative_to(library).as_posix()}", source.read_bytes(), record)
        _add(archive, f"{dist_info}/METADATA", ("\n".join(metadata) + "\n").encode(), record)
        _add(archive, f"{dist_info}/WHEEL", ("\n".join(wheel) + "\n").encode(), record)
        record.append(f"{dist_info}/RECORD,,")
        info = zipfile.ZipInfo(f"{dist_info}/RECORD", EPOCH)
        info.external_attr = 0o644 << 16
        archive.writestr(info, "\n".join(record) + "\n")
    return path


def stage(directory: pathlib.Path) -> pathlib.Path:
    """The extension's source folder: add-on modules, asset library, OSL shader, manifest and wheel."""
    source = directory / "paint_lut"
    (source / "wheels").mkdir(parents=True)
    for module in sorted((ROOT / "addon").glob("*.py")):
        shutil.copy2(module, source / module.name)
    # The bundled asset library (addon/library.py registers the folder).
    assets = ROOT / "addon" / "assets"
    (source / "assets").mkdir()
    for name in ASSETS:
        shutil.copy2(assets / name, source / "assets" / name)
    # The OSL variant's shader source (addon/osl.py compiles it).
    (source / "shaders").mkdir()
    for shader in sorted((ROOT / "addon" / "shaders").glob("*.osl")):
        shutil.copy2(shader, source / "shaders" / shader.name)
    shutil.copy2(ROOT / "blender_manifest.toml", source / "blender_manifest.toml")
    build_wheel(source / "wheels")
    return source


def builder_script() -> pathlib.Path:
    """blender_ext.py of the installed bpy module (Blender's extension builder)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("error: no Blender: pass --blender PATH or install the bpy module (scripts/bootstrap.sh)")
    for location in spec.submodule_search_locations:
        found = sorted(pathlib.Path(location).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return found[-1]
    raise SystemExit("error: the bpy module has no extension builder (blender_ext.py)")


def builder(blender: str | None) -> list[str]:
    """The command that runs Blender's extension builder."""
    blender = blender or shutil.which("blender")
    if blender:
        return [blender, "--factory-startup", "--command", "extension"]
    return [sys.executable, str(builder_script())]


def run(command: list[str]) -> None:
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"error: {' '.join(command[-4:])} failed:\n{done.stdout}{done.stderr}")


def untracked(root: pathlib.Path = ROOT) -> list[str]:
    """Files the zip would pack (lut/, addon/) that git does not track: a
    build packs what the repository holds, not what lies in a working copy.
    Empty outside a git checkout (a source archive holds only tracked files)."""
    try:
        done = subprocess.run(
            ["git", "ls-files", "--others", "--exclude-standard", "--", "lut", "addon"],
            cwd=root, capture_output=True, text=True,
        )  # fmt: skip
    except OSError:  # no git
        return []
    if done.returncode != 0:
        return []
    packed = {f"addon/assets/{name}" for name in ASSETS}
    return [
        name
        for name in done.stdout.splitlines()
        if (name.startswith("lut/") and name.endswith(".py"))
        or (name.startswith("addon/") and name.count("/") == 1 and name.endswith(".py"))
        or name in packed
        or (name.startswith("addon/shaders/") and name.endswith(".osl"))
    ]


def build(output_dir, blender: str | None = None) -> pathlib.Path:
    """Build and validate the extension zip; returns its path.  Refuses a
    working copy with untracked sources (``untracked``)."""
    check_versions()
    stray = untracked()
    if stray:
        raise SystemExit(
            "error: untracked files would go into the extension: " + ", ".join(stray) + " (commit or remove them)"
        )
    output_dir = pathlib.Path(output_dir).resolve()
    output_dir.mkdir(parents=True, exist_ok=True)
    target = output_dir / f"{manifest()['id']}-{manifest()['version']}.zip"
    command = builder(blender)
    with tempfile.TemporaryDirectory(prefix="paint_lut_build") as tmp:
        source = stage(pathlib.Path(tmp))
        # Build next to the staging folder, then move into place: a failed
        # build never replaces a good zip.
        partial = pathlib.Path(tmp) / target.name
        run([*command, "build", "--source-dir", str(source), "--output-filepath", str(partial)])
        run([*command, "validate", str(partial)])
        shutil.move(partial, target)
    return target


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output-dir", default=str(ROOT / "dist"), help="where the zip goes (default dist/)")
    parser.add_argument("--blender", help="Blender executable (default: blender on PATH, else the bpy module)")
    args = parser.parse_args(argv)
    print(build(args.output_dir, args.blender))
    return 0


if __name__ == "__main__":
    sys.exit(main())
