"""Fresnel reflectance in numpy: the host-side twin of glsl/microfacet.glsl, for packing and for tests."""

from __future__ import annotations

from functools import lru_cache

import numpy as np


def fresnel_dielectric(cos_i, eta):
    """Unpolarised reflectance for light arriving at cos_i from the side of index 1 into index eta."""
    cos_i = np.clip(np.asarray(cos_i, float), 0.0, 1.0)
    sin2_t = (1.0 - cos_i**2) / eta**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    return np.where(sin2_t >= 1.0, 1.0, 0.5 * (r_parl**2 + r_perp**2))


@lru_cache(maxsize=64)
def diffuse_fresnel_reflectance(eta: float) -> float:
    """Fraction of uniformly diffuse light (cosine-weighted) reflected at a boundary of relative index eta:
    the integral of 2 mu F(mu) over mu in [0, 1], by Gauss-Legendre quadrature."""
    nodes, weights = np.polynomial.legendre.leggauss(256)
    mu = 0.5 * (nodes + 1.0)
    return float(0.5 * np.sum(weights * 2.0 * mu * fresnel_dielectric(mu, eta)))


def internal_diffuse_reflectance(eta: float) -> float:
    """The same seen from inside a medium of index eta (used by plastic's diffuse base): by reciprocity,
    1 - F_int = (1 - F_ext) / eta^2."""
    return 1.0 - (1.0 - diffuse_fresnel_reflectance(eta)) / eta**2
