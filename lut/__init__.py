"""Paint LUT: physically based paint appearance from Germer's scattering models."""

__version__ = "0.1.0"
