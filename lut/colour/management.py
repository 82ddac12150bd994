"""Colour: spectra, working spaces and the spectral-to-RGB integration.

Every number comes from colour-science (no hand-typed matrices), but the ones
a bake needs are stored as data in ``lut.colour.data`` (made by
``scripts/make_colour_data.py``; a test recomputes them), so baking presets
and spectral paints does not import colour-science: Blender does not ship it
and it would pull scipy into the extension.  colour-science is needed only to
regenerate the data and to read spectra from its other datasets.

RGB values are scene-linear in a named working space, with the names Blender
uses: "Linear Rec.709" (default), "Linear Rec.2020", "ACEScg".  Spectra are
integrated with the CIE 1931 2° observer under D65 and adapted to the working
space's white with Bradford, so a flat spectrum of value v maps to the grey
RGB (v, v, v) in every space."""

from __future__ import annotations

import csv
import functools
import pathlib

import numpy as np

from ..models import _validate

#: Blender working-space names and their colour-science colourspaces.
WORKING_SPACES = {
    "Linear Rec.709": "ITU-R BT.709",
    "Linear Rec.2020": "ITU-R BT.2020",
    "ACEScg": "ACEScg",
}
DEFAULT_SPACE = "Linear Rec.709"

#: Wavelengths [nm] at which spectra are sampled and integrated.
WAVELENGTHS = np.arange(380.0, 781.0, 5.0)
WAVELENGTHS.setflags(write=False)


def _colour():
    import colour  # deferred: importing colour-science takes about a second

    return colour


def working_space(name: str) -> str:
    """Validate a working-space name."""
    if not isinstance(name, str) or name not in WORKING_SPACES:
        allowed = ", ".join(repr(k) for k in WORKING_SPACES)
        raise ValueError(f"space must be one of {allowed}, got {name!r}")
    return name


@functools.lru_cache(maxsize=8)
def spectral_weights(space: str = DEFAULT_SPACE) -> np.ndarray:
    """Matrix W (3, len(WAVELENGTHS)) with RGB = W @ values for a
    reflectance-like spectrum (stored data; see ``compute_spectral_weights``)."""
    from . import data as colour_data

    weights = np.array(colour_data.SPECTRAL_WEIGHTS[working_space(space)], dtype=float)
    weights.setflags(write=False)
    return weights


def rgb_to_rgb(source: str, target: str) -> np.ndarray:
    """3x3 matrix converting linear RGB of one working space to another
    (stored data; see ``compute_rgb_to_rgb``)."""
    from . import data as colour_data

    return np.array(colour_data.RGB_TO_RGB[f"{working_space(source)} -> {working_space(target)}"], dtype=float)


def compute_rgb_to_rgb(source: str, target: str) -> np.ndarray:
    """colour-science's RGB-to-RGB matrix with Bradford adaptation."""
    colour = _colour()
    return colour.matrix_RGB_to_RGB(
        colour.RGB_COLOURSPACES[WORKING_SPACES[working_space(source)]],
        colour.RGB_COLOURSPACES[WORKING_SPACES[working_space(target)]],
        chromatic_adaptation_transform="Bradford",
    )


def compute_spectral_weights(space: str = DEFAULT_SPACE) -> np.ndarray:
    """Matrix W (3, len(WAVELENGTHS)) with RGB = W @ values for a
    reflectance-like spectrum sampled at WAVELENGTHS: CIE 1931 2° colour
    matching functions times D65, normalized so that a flat spectrum of 1 has
    Y = 1, then XYZ -> working-space RGB with Bradford adaptation from D65:
    a flat spectrum of 1 gives RGB (1, 1, 1)."""
    colour = _colour()
    space = working_space(space)
    shape = colour.SpectralShape(WAVELENGTHS[0], WAVELENGTHS[-1], WAVELENGTHS[1] - WAVELENGTHS[0])
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    xyz = (cmfs.values * d65.values[:, None]).T  # (3, N)
    xyz = xyz / xyz[1].sum()
    # Adapt from the white this integration actually produces (the tabulated
    # D65 spectrum's, 2e-5 from the nominal D65 chromaticity), so a flat
    # spectrum maps exactly to grey.
    white = colour.XYZ_to_xy(xyz.sum(axis=1))
    to_rgb = colour.XYZ_to_RGB(
        np.eye(3), WORKING_SPACES[space], illuminant=white, chromatic_adaptation_transform="Bradford"
    ).T  # columns: RGB of the X, Y, Z unit vectors
    return to_rgb @ xyz


def spectrum_to_rgb(values, space: str = DEFAULT_SPACE) -> np.ndarray:
    """RGB of spectral values sampled at WAVELENGTHS (last axis)."""
    return np.asarray(values) @ spectral_weights(space).T


#: A spectrum's scale factor.
_SCALE = _validate.Range(0.0, None)


class Spectrum:
    """A spectral reflectance (or weight), sampled at WAVELENGTHS.

    Build it from a colour-science SpectralDistribution, a CSV file of
    ``wavelength,value`` rows (nm), a named colour-science dataset entry
    ``"<collection>/<name>"`` of ``colour.SDS_COLOURCHECKERS`` (for example
    ``"ColorChecker N Ohta/red"``), or (wavelengths, values) arrays.  Values
    outside the given range are held at the end values."""

    def __init__(self, source, values=None, *, name=None, scale=1.0):
        if isinstance(scale, bool) or not isinstance(scale, (int, float, np.floating, np.integer)):
            raise _validate.range_error(scale, "spectrum scale", _SCALE)  # not a number (float() would take text)
        _validate.check_range(scale, "spectrum scale", _SCALE)
        if values is not None:
            try:
                wl, val = np.asarray(source, dtype=float), np.asarray(values, dtype=float)
            except (TypeError, ValueError):
                raise ValueError("spectrum wavelengths and values must be lists of numbers") from None
            label = name or "array"
        elif isinstance(source, (str, pathlib.Path)) and str(source).lower().endswith(".csv"):
            wl, val = _read_csv(pathlib.Path(source))
            label = name or str(source)
        elif isinstance(source, str):
            wl, val = _dataset(source)
            label = name or source
        elif hasattr(source, "wavelengths") and hasattr(source, "values"):
            wl, val = np.asarray(source.wavelengths, dtype=float), np.asarray(source.values, dtype=float)
            label = name or getattr(source, "name", "SpectralDistribution")
        else:
            raise ValueError(
                "a spectrum must be a colour.SpectralDistribution, a .csv file of wavelength,value, "
                f"a 'collection/name' colour-science dataset entry or (wavelengths, values); got {source!r}"
            )
        if wl.ndim != 1 or wl.shape != val.shape or wl.size < 2 or not np.all(np.diff(wl) > 0):
            raise ValueError(f"spectrum {label!r}: wavelengths must increase and match the values")
        if not (np.all(np.isfinite(val)) and np.all(np.isfinite(wl))):
            raise ValueError(f"spectrum {label!r}: values must be finite")
        if wl[-1] <= WAVELENGTHS[0] or wl[0] >= WAVELENGTHS[-1]:
            hint = " (micrometres? give nanometres)" if wl[-1] < 10 else ""
            raise ValueError(
                f"spectrum {label!r}: wavelengths must be in nm and overlap {WAVELENGTHS[0]:g}-{WAVELENGTHS[-1]:g} nm, "
                f"got {wl[0]:g}-{wl[-1]:g}{hint}"
            )
        self.name = label
        self.values = np.interp(WAVELENGTHS, wl, val) * float(scale)
        self.values.setflags(write=False)

    @classmethod
    def flat(cls, value):
        return cls(WAVELENGTHS[[0, -1]], [value, value], name=f"flat {value}")

    def at(self, wavelength_nm):
        """Value at a wavelength (linear interpolation)."""
        return np.interp(wavelength_nm, WAVELENGTHS, self.values)

    def rgb(self, space: str = DEFAULT_SPACE):
        return spectrum_to_rgb(self.values, space)

    def key(self):
        """Canonical description: the sampled values (floats round-trip
        exactly through JSON)."""
        return [float(v) for v in self.values]

    def __eq__(self, other):
        return isinstance(other, Spectrum) and np.array_equal(self.values, other.values)

    def __hash__(self):
        return hash(self.values.tobytes())

    def __repr__(self):
        return f"Spectrum({self.name!r})"


def _read_csv(path: pathlib.Path):
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    except OSError as exc:
        raise ValueError(f"cannot read spectrum file {str(path)!r}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"spectrum file {str(path)!r} is not UTF-8 text (byte {exc.start})") from None
    except csv.Error as exc:
        raise ValueError(f"spectrum file {str(path)!r} is not CSV: {exc}") from None
    try:
        data = np.array([[float(r[0]), float(r[1])] for r in rows if _is_number(r[0])])
    except (ValueError, IndexError):
        raise ValueError(f"spectrum file {str(path)!r} must hold rows of wavelength,value") from None
    if data.ndim != 2 or len(data) < 2:
        raise ValueError(f"spectrum file {str(path)!r} must hold at least two rows of wavelength,value")
    return data[:, 0], data[:, 1]


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def _dataset(name: str):
    from . import data as colour_data

    if name in colour_data.SPECTRA:
        wavelengths, values = colour_data.SPECTRA[name]
        return np.array(wavelengths, dtype=float), np.array(values, dtype=float)
    try:
        colour = _colour()
    except ImportError:
        raise ValueError(
            f"spectrum {name!r} needs colour-science, which is not installed; stored without it: "
            f"{', '.join(sorted(colour_data.SPECTRA))}"
        ) from None
    collection, _, entry = name.partition("/")
    sds = colour.SDS_COLOURCHECKERS.get(collection)
    if sds is None or entry not in sds:
        raise ValueError(
            f"unknown spectrum {name!r}: use 'collection/name' from colour.SDS_COLOURCHECKERS, "
            f"e.g. 'ColorChecker N Ohta/red' (collections: {', '.join(sorted(colour.SDS_COLOURCHECKERS))})"
        )
    sd = sds[entry]
    return np.asarray(sd.wavelengths, dtype=float), np.asarray(sd.values, dtype=float)
