"""Fresnel reflectance in numpy: the host-side twin of glsl/microfacet.glsl, for packing and for tests."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from lenslab.render.gpu_layout import ROUGH_TABLE_SIZE  # the table's entries, as glsl/bsdf.glsl reads them


def fresnel_dielectric(cos_i, eta):
    """Unpolarised reflectance for light arriving at cos_i from the side of index 1 into index eta."""
    cos_i = np.clip(np.asarray(cos_i, float), 0.0, 1.0)
    sin2_t = (1.0 - cos_i**2) / eta**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    with np.errstate(invalid="ignore", divide="ignore"):  # 0/0 at grazing total reflection: replaced below
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


def _visible_normals(wo: np.ndarray, alpha: float, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """GGX visible normals of each wo (Heitz 2018), for a fixed stratified set of (u1, u2); numpy twin of
    glsl/microfacet.glsl's sampler. wo: (M, 3); returns (M, K, 3)."""
    wh = np.stack([alpha * wo[:, 0], alpha * wo[:, 1], wo[:, 2]], axis=1)
    wh /= np.linalg.norm(wh, axis=1, keepdims=True)
    t1 = np.stack([-wh[:, 1], wh[:, 0], np.zeros(len(wh))], axis=1)
    length = np.linalg.norm(t1, axis=1, keepdims=True)
    t1 = np.where(length > 0, t1 / np.maximum(length, 1e-30), [1.0, 0.0, 0.0])
    t2 = np.cross(wh, t1)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1 + wh[:, 2:3])
    p2 = (1 - s) * np.sqrt(np.maximum(0, 1 - p1**2)) + s * p2
    p3 = np.sqrt(np.maximum(0, 1 - p1**2 - p2**2))
    n = p1[..., None] * t1[:, None] + p2[..., None] * t2[:, None] + p3[..., None] * wh[:, None]
    m = np.stack([alpha * n[..., 0], alpha * n[..., 1], np.maximum(1e-6, n[..., 2])], axis=-1)
    return m / np.linalg.norm(m, axis=-1, keepdims=True)


def _smith_lambda(w: np.ndarray, alpha: float, distribution: str = "ggx") -> np.ndarray:
    """Smith's Lambda of each direction w (..., 3): GGX exactly, Beckmann by Walter et al.'s rational fit
    (as glsl/microfacet.glsl and Mitsuba)."""
    cos2 = np.maximum(w[..., 2] ** 2, 1e-12)
    tan2 = np.maximum(0, 1 - cos2) / cos2
    if distribution == "beckmann":
        a = 1.0 / np.maximum(alpha * np.sqrt(tan2), 1e-12)
        return np.where(a >= 1.6, 0.0, (1 - 1.259 * a + 0.396 * a**2) / (3.535 * a + 2.181 * a**2))
    return 0.5 * (np.sqrt(1 + alpha**2 * tan2) - 1)


def _beckmann_normals(alpha: float, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Beckmann microfacet normals drawn with density D(m) cos(theta_m), for a stratified set of (u1, u2);
    numpy twin of glsl/microfacet.glsl's beckmann_sample_normal. Returns (K, 3)."""
    tan2 = -alpha**2 * np.log1p(-u1)
    cos = 1 / np.sqrt(1 + tan2)
    sin = np.sqrt(np.maximum(0, 1 - cos**2))
    phi = 2 * np.pi * u2
    return np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], axis=-1)


@lru_cache(maxsize=64)
def rough_reflectance_table(eta: float, alpha: float, distribution: str = "ggx", size: int = ROUGH_TABLE_SIZE,
                            grid: int = 96) -> np.ndarray:
    """Directional albedo of a rough dielectric interface's reflection, R(mu) at mu = i / (size - 1):
    the integral of F D G / (4 mu) over outgoing directions, on a stratified grid of microfacet normals: GGX's
    visible normals of each incident direction (E = mean of F G / G1), or Beckmann normals drawn from
    D cos (E = mean of F G (wo.m) / (mu cos theta_m)). As Mitsuba's roughplastic, this is what the coating takes
    away from the light that reaches the diffuse base."""
    mu = np.maximum(np.arange(size) / (size - 1), 1e-6)
    wo = np.stack([np.sqrt(1 - mu**2), np.zeros(size), mu], axis=1)
    u1, u2 = (np.stack(np.meshgrid(np.arange(grid), np.arange(grid)), axis=-1).reshape(-1, 2).T + 0.5) / grid
    if distribution == "beckmann":
        m = np.broadcast_to(_beckmann_normals(alpha, u1, u2), (size, len(u1), 3))
    else:
        m = _visible_normals(wo, alpha, u1, u2)
    wo_dot_m = np.einsum("mk,mnk->mn", wo, m)
    wi = 2 * wo_dot_m[..., None] * m - wo[:, None, :]
    lam_o = _smith_lambda(wo, alpha, distribution)[:, None]
    g = 1 / (1 + lam_o + _smith_lambda(wi, alpha, distribution))
    if distribution == "beckmann":
        weight = g * np.maximum(wo_dot_m, 0) / (mu[:, None] * m[..., 2])
    else:
        weight = g * (1 + lam_o)  # G / G1(wo)
    value = np.where(wi[..., 2] > 0, fresnel_dielectric(wo_dot_m, eta) * weight, 0.0)
    return value.mean(axis=1)


def _refract(w: np.ndarray, m: np.ndarray, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """w (pointing away, on m's side) refracted through a boundary of relative index eta at normal m, and
    whether it got through (not total internal reflection). Shapes (..., 3)."""
    cos_i = np.einsum("...k,...k->...", w, m)
    sin2_t = np.maximum(0.0, 1.0 - cos_i**2) / eta**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    return -w / eta + (cos_i / eta - cos_t)[..., None] * m, sin2_t < 1.0


@lru_cache(maxsize=64)
def rough_transmittance_table(eta: float, alpha: float, distribution: str = "ggx", size: int = ROUGH_TABLE_SIZE,
                              grid: int = 96) -> np.ndarray:
    """Directional transmittance of a rough dielectric interface, T(mu) at mu = i / (size - 1): the share of
    light arriving at cos theta = mu that crosses into the material, (1 - F) G1(refracted) averaged over the
    visible normals (Mitsuba's eval_transmittance, which its roughplastic uses for the light that reaches the
    diffuse base and leaves it again). It is less than 1 - R: the microfacets also shadow part of what
    refracts. Beckmann normals are drawn from D cos and weighed to their visible density."""
    mu = np.maximum(np.arange(size) / (size - 1), 1e-6)
    wi = np.stack([np.sqrt(1 - mu**2), np.zeros(size), mu], axis=1)
    u1, u2 = (np.stack(np.meshgrid(np.arange(grid), np.arange(grid)), axis=-1).reshape(-1, 2).T + 0.5) / grid
    if distribution == "beckmann":
        m = np.broadcast_to(_beckmann_normals(alpha, u1, u2), (size, len(u1), 3))
        wi_dot_m = np.einsum("mk,mnk->mn", wi, m)
        visible = np.maximum(wi_dot_m, 0) / ((1 + _smith_lambda(wi, alpha, distribution))[:, None] * mu[:, None] * m[..., 2])
    else:
        m = _visible_normals(wi, alpha, u1, u2)
        wi_dot_m = np.einsum("mk,mnk->mn", wi, m)
        visible = np.ones_like(wi_dot_m)
    wt, through = _refract(np.broadcast_to(wi[:, None, :], m.shape), m, eta)
    g1_t = 1 / (1 + _smith_lambda(-wt, alpha, distribution))  # the refracted ray's masking, seen from below
    value = np.where(through & (wt[..., 2] < 0) & (wi_dot_m > 0), (1 - fresnel_dielectric(wi_dot_m, eta)) * g1_t, 0.0)
    return (value * visible).mean(axis=1)


@lru_cache(maxsize=64)
def rough_internal_reflectance(eta: float, alpha: float, distribution: str = "ggx") -> float:
    """Cosine-weighted mean reflectance of the same interface seen from inside (relative index 1/eta):
    2 * integral of R(mu) mu dmu, by the trapezoid rule over the table."""
    mu = np.arange(ROUGH_TABLE_SIZE) / (ROUGH_TABLE_SIZE - 1)
    return float(np.trapezoid(2 * rough_reflectance_table(1.0 / eta, alpha, distribution) * mu, mu))
