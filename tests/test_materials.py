"""Every BSDF against physics: sampling agrees with evaluation (chi-square, as pbrt and Mitsuba test),
energy is conserved (white furnaces), glass bends light where the lens-maker's formula says, and absorption
follows Beer-Lambert."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy import stats

from lenslab.render.tracer import RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.materials import Conductor, Diffuse, Dielectric, Emissive, Plastic, ThinDielectric
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import Box, Rectangle, Sphere
from lenslab.scene.transform import Transform
from tests.bsdf_probe import BsdfProbe
from tests.helpers import render_to_spp

PERFECT_MIRROR = dict(metal="custom", eta=(0.0, 0.0, 0.0), k=(50.0, 50.0, 50.0))  # reflectance exactly 1


def direction(theta_deg, phi_deg=30.0):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


# -- sampling agrees with the pdf ------------------------------------------------------------------------
SAMPLED = {
    "diffuse": Diffuse((0.7, 0.5, 0.3)),
    "rough gold": Conductor(metal="gold", roughness=0.6),
    "rough aluminium": Conductor(metal="aluminium", roughness=0.35),
    "smooth plastic": Plastic((0.6, 0.2, 0.2), roughness=0.0),
    "rough plastic": Plastic((0.2, 0.5, 0.7), roughness=0.5),
    "rough glass": Dielectric(ior=1.5, roughness=0.7),
    "beckmann gold": Conductor(metal="gold", roughness=0.5, distribution="beckmann"),
    "beckmann plastic": Plastic((0.2, 0.5, 0.7), roughness=0.4, distribution="beckmann"),
    "beckmann glass": Dielectric(ior=1.5, roughness=0.85, distribution="beckmann"),  # wide enough for the bins
}

N_THETA, N_PHI, SUB = 20, 40, 12


def bin_directions():
    """Midpoints of SUB x SUB cells inside each (cos theta, phi) bin: equal solid angle everywhere."""
    cos_edges = np.linspace(-1, 1, N_THETA * SUB + 1)
    phi_edges = np.linspace(0, 2 * np.pi, N_PHI * SUB + 1)
    c = 0.5 * (cos_edges[1:] + cos_edges[:-1])
    p = 0.5 * (phi_edges[1:] + phi_edges[:-1])
    cc, pp = np.meshgrid(c, p, indexing="ij")
    s = np.sqrt(1 - cc**2)
    return np.stack([s * np.cos(pp), s * np.sin(pp), cc], axis=-1).reshape(-1, 3)


def histogram(wi):
    cos_bin = np.clip(((wi[:, 2] + 1) / 2 * N_THETA).astype(int), 0, N_THETA - 1)
    phi = np.mod(np.arctan2(wi[:, 1], wi[:, 0]), 2 * np.pi)
    phi_bin = np.clip((phi / (2 * np.pi) * N_PHI).astype(int), 0, N_PHI - 1)
    return np.bincount(cos_bin * N_PHI + phi_bin, minlength=N_THETA * N_PHI).astype(float)


def chi_square_p_value(observed, expected, min_expected=5.0):
    """Pearson's test after pooling bins with few expected counts (pbrt-v4's and Mitsuba's recipe)."""
    order = np.argsort(expected)
    obs, exp = observed[order], expected[order]
    pooled_obs, pooled_exp, acc_o, acc_e = [], [], 0.0, 0.0
    for o, e in zip(obs, exp):
        acc_o, acc_e = acc_o + o, acc_e + e
        if acc_e >= min_expected:
            pooled_obs.append(acc_o)
            pooled_exp.append(acc_e)
            acc_o = acc_e = 0.0
    if acc_e > 0 and pooled_exp:
        pooled_obs[-1] += acc_o
        pooled_exp[-1] += acc_e
    pooled_obs, pooled_exp = np.array(pooled_obs), np.array(pooled_exp)
    chi2 = np.sum((pooled_obs - pooled_exp) ** 2 / pooled_exp)
    return stats.chi2.sf(chi2, len(pooled_exp) - 1)


@pytest.mark.parametrize("name", list(SAMPLED))
@pytest.mark.parametrize("theta", [10.0, 55.0, 80.0])
def test_sampled_directions_follow_the_pdf(renderer, name, theta):
    probe = BsdfProbe(renderer, SAMPLED[name])
    try:
        wo = direction(theta)
        n = 400_000
        u = np.random.default_rng(7).random((n, 3))
        samples = probe.sample(wo, u)
        smooth = samples.ok & ~samples.delta
        observed = histogram(samples.wi[smooth])
        _, pdf = probe.evaluate(wo, bin_directions())
        cell_solid_angle = 4 * np.pi / (N_THETA * N_PHI * SUB * SUB)
        expected = n * (pdf * cell_solid_angle).reshape(N_THETA, SUB, N_PHI, SUB).sum(axis=(1, 3)).reshape(-1)
        # Failed samples (directions below the horizon) and a smooth coating's mirror reflections are one more
        # bin: the pdf of the rest integrates to less than 1.
        observed = np.append(observed, (~smooth).sum())
        expected = np.append(expected, max(n - expected.sum(), 0.0))
        assert abs(expected.sum() - n) < 1e-3 * n + 1
        # 18 tests: a Bonferroni-corrected significance level of 1%.
        assert chi_square_p_value(observed, expected) > 0.01 / len(SAMPLED) / 3

        # Sample weights are exactly f |cos| / pdf of the same direction.
        f, pdf_again = probe.evaluate(wo, samples.wi[smooth][:2000])
        np.testing.assert_allclose(pdf_again, samples.pdf[smooth][:2000], rtol=2e-3)
        np.testing.assert_allclose(samples.weight[smooth][:2000], f / pdf_again[:, None], rtol=2e-3, atol=1e-6)
    finally:
        probe.release()


def test_chi_square_catches_a_wrong_pdf(renderer):
    # The same test fails when the samples come from another lobe: it can fail.
    probe = BsdfProbe(renderer, Conductor(metal="gold", roughness=0.6))
    other = BsdfProbe(renderer, Conductor(metal="gold", roughness=0.5))
    try:
        wo, n = direction(55.0), 400_000
        samples = other.sample(wo, np.random.default_rng(7).random((n, 3)))
        _, pdf = probe.evaluate(wo, bin_directions())
        expected = n * (pdf * 4 * np.pi / (N_THETA * N_PHI * SUB * SUB)).reshape(N_THETA, SUB, N_PHI, SUB).sum(axis=(1, 3)).reshape(-1)
        observed = np.append(histogram(samples.wi[samples.ok]), (~samples.ok).sum())
        expected = np.append(expected, max(n - expected.sum(), 0.0))
        assert chi_square_p_value(observed, expected) < 1e-6
    finally:
        probe.release()
        other.release()


# -- energy: white furnaces ------------------------------------------------------------------------------
def furnace(material, max_depth=64):
    return Scene(
        camera=ThinLensCamera(position=(0, 0, 3), look_at=(0, 0, 0), focal_length_mm=50, f_number=8,
                              focus_distance_m=3, resolution=(32, 32)),
        environment=ConstantEnvironment((1.0, 1.0, 1.0)),
        render=RenderSettings(max_depth=max_depth, rr_depth=16),
        materials={"m": material},
        nodes=[Node("ball", shape=Sphere(0.5), material="m")],
    )


def render_mean(renderer, scene, spp):
    session = RenderSession(renderer, scene)
    image = render_to_spp(session, spp).image()
    session.release()
    return image


def sphere_pixels(image):
    h, w = image.shape[:2]
    y, x = np.mgrid[0:h, 0:w] + 0.5
    # The ball's silhouette: radius 0.5 at 3 m with a 50 mm lens on a 36 mm sensor -> 0.46 of the half-width.
    return np.hypot(x - w / 2, y - h / 2) < 0.4 * w / 2


@pytest.mark.parametrize("material", [
    Dielectric(ior=1.5),
    Dielectric(ior=0.75),  # an air bubble in water: relative index below 1, total internal reflection from outside
    ThinDielectric(ior=1.5),
    Conductor(**PERFECT_MIRROR),
], ids=["smooth glass", "smooth bubble", "thin glass", "perfect mirror"])
def test_lossless_smooth_materials_keep_all_energy(renderer, material):
    image = render_mean(renderer, furnace(material), spp=64)
    ball = image[sphere_pixels(image)]
    assert ball.mean() == pytest.approx(1.0, abs=0.01)
    assert np.abs(image - 1.0).max() < 0.25


@pytest.mark.parametrize("material", [
    Conductor(roughness=0.3, **PERFECT_MIRROR),
    Dielectric(ior=1.5, roughness=0.3),
    Plastic((1.0, 1.0, 1.0), roughness=0.6),
    Plastic((1.0, 1.0, 1.0), roughness=0.0),
], ids=["rough mirror", "rough glass", "rough white plastic", "smooth white plastic"])
def test_rough_materials_never_create_energy(renderer, material):
    image = render_mean(renderer, furnace(material), spp=64)
    ball = image[sphere_pixels(image)]
    assert ball.mean() <= 1.0 + 0.01
    # Single-scattering microfacet models lose the light that would scatter between microfacets: a little
    # at this roughness (a GGX alpha of 0.64 loses 45% at normal incidence; test_rough_conductor_albedo).
    # Rough plastic follows Mitsuba's roughplastic, whose diffuse base loses more (about 30% when white).
    assert ball.mean() > (0.6 if isinstance(material, Plastic) and material.roughness > 0 else 0.85)


def assert_mirror_albedo_matches_integral(renderer, material, d_of_cos2, lam, seed):
    """The directional albedo of a perfect microfacet mirror, from the GPU's sampling, against a numpy integral
    of D G / (4 cos_o cos_i) cos_i over the hemisphere, for D (a function of cos^2 of the microfacet normal)
    and Smith's Lambda written in the test from the formulas; G is height-correlated, as ours."""
    probe = BsdfProbe(renderer, material)
    rng = np.random.default_rng(seed)
    wi = rng.normal(size=(1_000_000, 3))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wi[:, 2] = np.abs(wi[:, 2])
    try:
        for theta in (5.0, 45.0, 75.0):
            wo = direction(theta)
            m = wi + wo
            m /= np.linalg.norm(m, axis=1, keepdims=True)
            f_cos = d_of_cos2(m[:, 2] ** 2) / (1 + lam(wo) + lam(wi)) / (4 * wo[2])
            reference = f_cos.mean() * 2 * np.pi
            sampled = probe.sample(wo, rng.random((400_000, 3))).weight[:, 0].mean()
            assert sampled == pytest.approx(reference, rel=0.01)
    finally:
        probe.release()


def test_rough_conductor_albedo_matches_numerical_integration(renderer):
    # A perfect GGX mirror (alpha 0.64).
    alpha = 0.64

    def lam(w):
        c2 = w[..., 2] ** 2
        return 0.5 * (np.sqrt(1 + alpha**2 * (1 - c2) / c2) - 1)

    assert_mirror_albedo_matches_integral(
        renderer, Conductor(roughness=0.8, **PERFECT_MIRROR),
        lambda cos2: alpha**2 / (np.pi * (cos2 * (alpha**2 - 1) + 1) ** 2), lam, seed=3)


def test_beckmann_albedo_matches_numerical_integration(renderer):
    # The same check for Beckmann (Mitsuba's default distribution), whose normals are drawn from D cos rather
    # than from the visible normals: Beckmann's D and Walter et al.'s Lambda.
    alpha = 0.5

    def lam(w):
        a = 1 / (alpha * np.sqrt(np.maximum(1 - w[..., 2] ** 2, 1e-12)) / w[..., 2])
        return np.where(a >= 1.6, 0.0, (1 - 1.259 * a + 0.396 * a**2) / (3.535 * a + 2.181 * a**2))

    assert_mirror_albedo_matches_integral(
        renderer, Conductor(roughness=math.sqrt(alpha), distribution="beckmann", **PERFECT_MIRROR),
        lambda cos2: np.exp(-(1 - cos2) / cos2 / alpha**2) / (np.pi * alpha**2 * cos2**2), lam, seed=4)


def test_beckmann_evaluates_as_mitsuba(renderer, mitsuba):
    # f |cos| of a Beckmann conductor against Mitsuba 3's own roughconductor, where masking is negligible
    # (Mitsuba's G is separable, ours height-correlated: they part only at grazing angles).
    mi = mitsuba
    eta, k, alpha = (0.2, 0.92, 1.1), (3.9, 2.45, 2.14), 0.2
    theirs = mi.load_dict({"type": "roughconductor", "distribution": "beckmann", "alpha": alpha,
                           "eta": {"type": "rgb", "value": eta}, "k": {"type": "rgb", "value": k}})
    probe = BsdfProbe(renderer, Conductor(metal="custom", eta=eta, k=k, roughness=math.sqrt(alpha),
                                          distribution="beckmann"))
    try:
        for theta_o in (0.0, 20.0, 40.0):
            wo = direction(theta_o, 10.0)
            wi = np.array([direction(t, p) for t in (5.0, 15.0, 30.0) for p in (190.0, 150.0, 100.0)])
            ours, _ = probe.evaluate(wo, wi)
            def vectors(v):
                v = np.broadcast_to(np.asarray(v, np.float32), (len(wi), 3))
                return mi.Vector3f(*(mi.Float(np.ascontiguousarray(v[:, i])) for i in range(3)))

            si = mi.SurfaceInteraction3f()
            si.wi = vectors(wo)
            si.sh_frame = mi.Frame3f(vectors((0.0, 0.0, 1.0)))
            value = theirs.eval(mi.BSDFContext(), si, vectors(wi))
            expected = np.array([np.array(value.x), np.array(value.y), np.array(value.z)]).T
            keep = expected[:, 1] > 1e-3
            assert keep.sum() >= 4
            np.testing.assert_allclose(ours[keep], expected[keep], rtol=0.03)
    finally:
        probe.release()


# -- glass optics --------------------------------------------------------------------------------------
def refract_through(probe, wo, front_face):
    """The transmitted direction for wo at a surface with normal +Z (forcing the refraction branch)."""
    s = probe.sample(wo, np.array([[0.5, 0.5, 0.999999]]), front_face=front_face)
    assert s.ok[0] and s.delta[0]
    return s.wi[0]


def test_glass_ball_focuses_parallel_light_where_the_lens_makers_formula_says(renderer):
    # A ball lens of index n and radius R focuses paraxial light at n R / (2 (n - 1)) from its centre.
    n, radius = 1.5, 1.0
    probe = BsdfProbe(renderer, Dielectric(ior=n))
    crossings = []
    try:
        for height in (0.01, 0.02, 0.04):
            o, d = np.array([0.0, height, -5.0]), np.array([0.0, 0.0, 1.0])
            for front in (True, False):
                # Hit the sphere (from outside: near root; from inside: far root).
                b = o @ d
                root = math.sqrt(b * b - (o @ o - radius**2))
                p = o + d * (-b - root if front else -b + root)
                normal = p / radius if front else -p / radius  # the normal on the side the ray arrives from
                frame = np.linalg.qr(np.column_stack([normal, [1, 0, 0], [0, 1, 0]]))[0]
                frame = np.column_stack([frame[:, 1], frame[:, 2], frame[:, 0] * np.sign(frame[:, 0] @ normal)])
                wo_local = frame.T @ -d
                d = frame @ refract_through(probe, wo_local, front_face=front)
                o = p
            crossings.append(o[2] - o[1] * d[2] / d[1])  # where the ray meets the axis
    finally:
        probe.release()
    focal = n * radius / (2 * (n - 1))
    assert crossings[0] == pytest.approx(focal, rel=0.005)
    assert crossings[0] >= crossings[1] >= crossings[2]  # spherical aberration: outer rays focus shorter


def test_absorption_follows_beer_lambert(renderer):
    # Looking through a slab of almost index-matched glass (no Fresnel loss) at a white backdrop.
    thickness, color, distance = 0.3, (0.5, 0.7, 0.9), 0.1
    glass = Dielectric(ior=1.0001, absorption_color=color, absorption_distance_m=distance)
    scene = Scene(
        camera=ThinLensCamera(position=(0, 0, 3), look_at=(0, 0, 0), focal_length_mm=200, f_number=16,
                              focus_distance_m=3, resolution=(16, 16)),
        render=RenderSettings(max_depth=8),
        materials={"glass": glass, "backdrop": Emissive((1.0, 1.0, 1.0))},
        nodes=[Node("slab", shape=Box((2.0, 2.0, thickness)), material="glass"),
               Node("backdrop", Transform(translate=(0, 0, -2)), Rectangle((20, 20)), "backdrop")],
    )
    image = render_mean(renderer, scene, spp=16)
    sigma = np.array(glass.absorption_coefficient())
    expected = np.exp(-sigma * thickness)
    assert np.allclose(expected, np.power(color, thickness / distance))  # the artist's colour at a distance
    np.testing.assert_allclose(image[6:10, 6:10].reshape(-1, 3).mean(axis=0), expected, rtol=0.01)


@pytest.mark.parametrize("distribution", ["ggx", "beckmann"])
def test_a_rough_coatings_transmittance_is_what_neither_reflects_nor_shadows(distribution):
    # Plastic's single-scattering coating (Mitsuba's roughplastic) lets through the rough interface's
    # transmittance: the smooth Fresnel value when nearly smooth, never more than what it does not reflect,
    # and less the rougher it is (its microfacets shadow part of what refracts).
    from lenslab.render.fresnel import fresnel_dielectric, rough_reflectance_table, rough_transmittance_table

    mu = np.arange(64) / 63
    smooth = rough_transmittance_table(1.5, 1e-4, distribution)
    np.testing.assert_allclose(smooth[8:], 1 - fresnel_dielectric(mu[8:], 1.5), atol=2e-3)
    previous = smooth
    for alpha in (0.1, 0.3, 0.6, 1.0):
        t = rough_transmittance_table(1.5, alpha, distribution)
        assert np.all(t <= 1 - rough_reflectance_table(1.5, alpha, distribution) + 1e-3)
        assert np.all(t[40:] <= previous[40:] + 1e-3) and t[48] < previous[48]  # (at grazing, roughness lets more in)
        previous = t
