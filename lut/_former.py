"""The library's module paths before it was layered into subpackages, kept
working for one release: ``import lut.fitting``, ``from lut import fitting``
and ``from lut.fitting import fit_lut`` give the module at its new path
(``lut.render.fitting``) with a DeprecationWarning.  ``lut.render`` and
``lut.paint`` are packages now; they answer their former names themselves.

One table, ``FORMER``, and one meta-path finder: no stub file per old name."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: Former module (under the package) -> its path now.
FORMER = {
    "colour_management": "colour.management",
    "colour_data": "colour.data",
    "schema": "paint.schema",
    "presets": "paint.presets",
    "gloss": "paint.gloss",
    "exr": "lutfiles.exr",
    "lutfile": "lutfiles.format",
    "files": "lutfiles.files",
    "table": "lutfiles.table",
    "angles": "lutfiles.angles",
    "cleanup": "lutfiles.cleanup",
    "baking": "lutfiles.baking",
    "closures": "render.closures",
    "nnls": "render.nnls",
    "fitting": "render.fitting",
    "eevee": "render.eevee",
    "eevee_tables": "render.eevee_tables",
    "principled": "render.principled",
}


def warn(package: str, name: str, stacklevel: int = 3) -> str:
    """Warn that ``package.name`` moved; return its path now."""
    now = f"{package}.{FORMER[name]}"
    warnings.warn(f"{package}.{name} is deprecated: import {now}", DeprecationWarning, stacklevel=stacklevel)
    return now


class _Loader(importlib.abc.Loader):
    def __init__(self, package: str, name: str):
        self.package, self.name = package, name

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        # The import system returns whatever sys.modules holds under the name
        # once this returns: the module at its new path.
        sys.modules[module.__name__] = importlib.import_module(warn(self.package, self.name, stacklevel=2))


class Finder(importlib.abc.MetaPathFinder):
    """Finds ``<package>.<former name>`` for the package it was made for."""

    def __init__(self, package: str):
        self.package = package

    def find_spec(self, fullname, path=None, target=None):
        head, _, name = fullname.rpartition(".")
        if head != self.package or name not in FORMER:
            return None
        return importlib.util.spec_from_loader(fullname, _Loader(self.package, name))


def install(package: str) -> None:
    """Put the finder for ``package`` first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, Finder) and f.package == package for f in sys.meta_path):
        sys.meta_path.insert(0, Finder(package))
