"""LensLab: a photographic studio on a physically based GPU path tracer."""

__version__ = "0.1.0"
