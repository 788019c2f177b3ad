"""The reference lens tracer (tests/reference_lens.py) against results known in closed form: the thick-lens
lensmaker's formula, Snell's law and total internal reflection, the Gaussian lens equation, the cos^4 law of
illumination and the pinhole camera. The product's real-lens code is tested against this reference, so the
reference is tested first, against physics alone."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests import reference_lens as rl

BK7_ND, BK7_VD = 1.5168, 64.17  # Schott N-BK7


def thick_lens(n, r1, r2, d):
    """(EFL, BFD, FFD) of a single thick lens in air, from the lensmaker's formula:
    1/f = (n-1) [1/R1 - 1/R2 + (n-1) d / (n R1 R2)], BFD = f (1 - (n-1) d / (n R1)), FFD = f (1 + (n-1) d / (n R2))."""
    f = 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * d / (n * r1 * r2)))
    return f, f * (1.0 - (n - 1.0) * d / (n * r1)), f * (1.0 + (n - 1.0) * d / (n * r2))


# A biconvex lens (R1 = 100, R2 = -100, 1 mm thick, n = 1.5) with a stop 1 mm in front of it.
BICONVEX = [(0.0, 1.0, 1.0, 20.0), (100.0, 1.0, 1.5, 30.0), (-100.0, 50.0, 1.0, 30.0)]

# A made-up Cooke-triplet-like lens, for properties that hold for any lens.
TRIPLET = [
    (22.0, 3.5, 1.62, 16.0),
    (-400.0, 4.0, 1.0, 16.0),
    (-21.0, 1.2, 1.62, 10.0),
    (20.0, 2.0, 1.0, 10.0),
    (0.0, 2.0, 1.0, 9.0),
    (80.0, 3.0, 1.62, 14.0),
    (-18.0, 40.0, 1.0, 14.0),
]


def test_biconvex_focal_length_and_focal_distances_match_the_thick_lens_formulas():
    f, bfd, ffd = thick_lens(1.5, 100.0, -100.0, 1.0)
    assert rl.paraxial_focal_length(BICONVEX) == pytest.approx(f, rel=1e-4)
    assert rl.back_focal_distance(BICONVEX) == pytest.approx(bfd, rel=1e-4)
    # The front focal distance is measured from the front vertex, which is the stop, 1 mm ahead of the glass.
    assert rl.front_focal_distance(BICONVEX) + 1.0 == pytest.approx(ffd, rel=1e-4)
    # Much tighter than asked: the only error of a real ray at 1e-4 of the aperture is ~(1e-4)^2 aberration.
    assert rl.paraxial_focal_length(BICONVEX) == pytest.approx(f, rel=1e-8)


@pytest.mark.parametrize("n, r1, r2, d", [(1.5, 60.0, -200.0, 8.0), (1.7, 40.0, 120.0, 5.0), (1.6, -80.0, -30.0, 6.0)])
def test_thick_lenses_of_other_shapes(n, r1, r2, d):
    """A strong thick lens, a positive meniscus and a negative meniscus (negative focal length: diverging)."""
    lens = [(r1, d, n, 20.0), (r2, 50.0, 1.0, 20.0)]
    f, bfd, ffd = thick_lens(n, r1, r2, d)
    cp = rl.cardinal_points(lens)
    assert cp.efl == pytest.approx(f, rel=1e-6)
    assert cp.efl_front == pytest.approx(f, rel=1e-6)  # air on both sides: the two focal lengths agree
    assert cp.bfd == pytest.approx(bfd, rel=1e-6)
    assert cp.ffd == pytest.approx(ffd, rel=1e-6)


@pytest.mark.parametrize("flat_first", [False, True])
def test_plano_convex_focal_length_is_r_over_n_minus_1(flat_first):
    """Either way round and whatever its thickness, a plano-convex lens has f = R / (n - 1). A flat refracting
    surface is written with an infinite radius."""
    n, r = 1.5, 51.68
    if flat_first:
        lens = [(math.inf, 6.0, n, 25.0), (-r, 60.0, 1.0, 25.0)]
    else:
        lens = [(r, 6.0, n, 25.0), (math.inf, 60.0, 1.0, 25.0)]
    assert rl.paraxial_focal_length(lens) == pytest.approx(r / (n - 1.0), rel=1e-4)


def test_refract_obeys_snells_law_and_reflects_totally_beyond_the_critical_angle():
    normal = np.array([[0.0, 0.0, 1.0]])
    for deg in (0.0, 10.0, 30.0, 41.0):
        i = math.radians(deg)
        d = np.array([[math.sin(i), 0.0, math.cos(i)]])
        for eta in (1.0 / 1.5, 1.5):
            t, ok = rl.refract(d, normal, eta)
            if eta * math.sin(i) <= 1.0:
                assert ok[0]
                assert t[0, 0] == pytest.approx(eta * math.sin(i), abs=1e-14)  # n1 sin i = n2 sin t
                assert t[0, 2] > 0.0 and np.linalg.norm(t[0]) == pytest.approx(1.0, abs=1e-14)
    critical = math.asin(1.0 / 1.5)
    for i in (critical - 1e-6, critical + 1e-6, math.radians(60.0)):
        _, ok = rl.refract(np.array([[math.sin(i), 0.0, math.cos(i)]]), normal, 1.5)
        assert ok[0] == (i < critical)


def test_a_steep_ray_inside_glass_is_lost_to_total_internal_reflection():
    """Rays parallel to the axis enter a flat face undeviated and meet a rear surface of radius 10 at height h,
    at incidence asin(h / 10): beyond the critical angle asin(1 / 1.5) = 41.8 degrees (h > 6.67) they are lost;
    below it they leave at asin(1.5 h / 10) to the normal."""
    lens = [(math.inf, 5.0, 1.5, 18.0), (-10.0, 50.0, 1.0, 18.0)]
    heights = np.array([0.0, 3.0, 6.0, 6.6, 6.7, 8.0])
    o = np.stack([np.zeros_like(heights), heights, np.full_like(heights, -1.0)], axis=1)
    p, t, ok = rl.trace(lens, o, [0.0, 0.0, 1.0], from_sensor=False)
    assert list(ok) == [True, True, True, True, False, False]
    for k in range(4):
        normal = (p[k] - np.array([0.0, 0.0, 5.0 - 10.0])) / 10.0
        sin_t = np.linalg.norm(np.cross(normal, t[k]))
        assert sin_t == pytest.approx(1.5 * heights[k] / 10.0, abs=1e-12)
    assert np.all(np.isnan(p[~ok]))


def test_rays_outside_a_clear_aperture_are_lost():
    # The stop (diameter 10) in front of the biconvex lens, and the lens's own clear aperture (diameter 30).
    lens = [(0.0, 1.0, 1.0, 10.0), (100.0, 1.0, 1.5, 30.0), (-100.0, 50.0, 1.0, 30.0)]
    heights = np.array([0.0, 4.9, 4.999, 5.001, 5.1, 8.0])
    o = np.stack([heights, np.zeros_like(heights), np.full_like(heights, -1.0)], axis=1)
    _, _, ok = rl.trace(lens, o, [0.0, 0.0, 1.0], from_sensor=False)
    assert list(ok) == [True, True, True, False, False, False]
    # Past the stop, a steep ray through its centre meets the lens 1 mm on, at height 1 tan(a): lost beyond 15 mm.
    for angle, passes in ((math.atan(14.9), True), (math.atan(15.1), False)):
        d = [math.sin(angle), 0.0, math.cos(angle)]
        _, _, ok = rl.trace([(0.0, 1.0, 1.0, 10.0), (math.inf, 50.0, 1.0, 30.0)], [0.0, 0.0, 0.0], d, from_sensor=False)
        assert ok == passes


def test_tracing_is_reversible():
    """Light retraces its path: rays traced from the scene, reversed and traced from the sensor, come back along
    the lines they started on."""
    rng = np.random.default_rng(1)
    n = 500
    o = np.stack([rng.uniform(-6, 6, n), rng.uniform(-6, 6, n), np.full(n, -30.0)], axis=1)
    d = np.stack([rng.uniform(-0.1, 0.1, n), rng.uniform(-0.1, 0.1, n), np.ones(n)], axis=1)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p, t, ok = rl.trace(TRIPLET, o, d, from_sensor=False)
    assert 50 < ok.sum() < n  # some get through, some are vignetted
    z_sensor = rl.default_sensor_z(TRIPLET)
    start = p[ok] + t[ok] * ((z_sensor - p[ok, 2]) / t[ok, 2])[:, None]  # on the sensor
    back_p, back_t, back_ok = rl.trace(TRIPLET, start, -t[ok], from_sensor=True)
    assert back_ok.all()
    np.testing.assert_allclose(back_t, -d[ok], atol=1e-12)
    # The original origin lies on the returning line.
    offset = o[ok] - back_p
    np.testing.assert_allclose(np.cross(offset, back_t), 0.0, atol=1e-9)


def test_cardinal_points_of_a_multi_element_lens_are_consistent():
    cp = rl.cardinal_points(TRIPLET)
    assert cp.efl > 0.0
    assert cp.efl_front == pytest.approx(cp.efl, rel=1e-7)
    # An object at the front focal point images at infinity: rays from it leave the lens parallel.
    o = np.array([[0.0, 0.0, cp.z_front_focal]] * 3)
    d = np.array([[0.0, 1e-5, 1.0], [0.0, 2e-5, 1.0], [1e-5, 0.0, 1.0]])
    _, t, ok = rl.trace(TRIPLET, o, d, from_sensor=False)
    assert ok.all()
    np.testing.assert_allclose(t[:, :2], 0.0, atol=1e-12)


@pytest.mark.parametrize("object_distance", [400.0, 1000.0, 3000.0, math.inf])
def test_best_focus_of_a_weak_slow_lens_matches_the_gaussian_lens_equation(object_distance):
    """1/s + 1/s' = 1/f, with s measured from the front principal plane H and s' from the rear one H', both found
    by tracing real rays (cardinal_points)."""
    lens = [(0.0, 1.0, 1.0, 4.0), (200.0, 3.0, 1.5, 20.0), (-200.0, 100.0, 1.0, 20.0)]  # f ~ 200, f/50
    cp = rl.cardinal_points(lens)
    if math.isinf(object_distance):
        z_image = cp.z_rear_focal
    else:
        s = cp.z_front_principal + object_distance  # the object is at z = -object_distance
        z_image = cp.z_rear_principal + cp.efl * s / (s - cp.efl)
    best = rl.best_focus_sensor_z(lens, object_distance)
    s_image = z_image - cp.z_rear_principal
    assert best.z_sensor == pytest.approx(z_image, abs=1e-3 * s_image)
    assert 0.0 < best.rms_radius_mm <= best.max_radius_mm < 1e-3


def test_best_focus_is_the_minimum_of_the_rms_spot_and_stopping_down_shrinks_it():
    """The closed-form minimum against a scan of the RMS spot around it; a fast lens (the triplet) has a real
    spherical-aberration blur that shrinks when the stop closes, and its best focus moves."""
    best = rl.best_focus_sensor_z(TRIPLET, 2000.0, n_rays=10_000)
    rms, biggest = rl.spot_size(TRIPLET, 2000.0, best.z_sensor, n_rays=10_000)
    assert rms == pytest.approx(best.rms_radius_mm, rel=1e-9)
    assert biggest == pytest.approx(best.max_radius_mm, rel=1e-9)
    scan = [rl.spot_size(TRIPLET, 2000.0, best.z_sensor + dz, n_rays=10_000)[0] for dz in np.linspace(-0.2, 0.2, 41)]
    assert min(scan) >= best.rms_radius_mm * (1.0 - 1e-12)
    assert scan[20] == pytest.approx(best.rms_radius_mm, rel=1e-9)  # dz = 0 in the middle of the scan
    assert scan[0] > best.rms_radius_mm and scan[-1] > best.rms_radius_mm
    stopped = rl.best_focus_sensor_z(TRIPLET, 2000.0, 0.5, n_rays=10_000)
    assert stopped.rms_radius_mm < 0.5 * best.rms_radius_mm


def test_a_pinhole_camera_has_exact_field_angles_and_cos4_falloff():
    """A lens that is only a stop: the chief ray is the straight line from the film point through the pinhole,
    and the irradiance falls off as cos^4 of its angle (up to (a/d)^2 = 1e-4 for a pinhole of radius a = 0.5 at
    d = 50)."""
    pinhole = [(0.0, 50.0, 1.0, 1.0)]
    radii = np.array([5.0, 20.0, 35.0, 50.0])
    angles = np.array([rl.chief_ray_angle(pinhole, 50.0, r) for r in radii])
    np.testing.assert_allclose(angles, np.arctan(radii / 50.0), rtol=1e-12)
    ill = rl.relative_illumination(pinhole, 50.0, radii, n_rays=100_000)
    np.testing.assert_allclose(ill.relative, np.cos(angles) ** 4, rtol=2e-3)
    # The raw irradiance on axis is L * pi a^2 / d^2 (to (a/d)^2) for unit radiance L.
    assert ill.irradiance_on_axis == pytest.approx(math.pi * 0.25 / 50.0**2, rel=2e-3)
    assert rl.relative_illumination(pinhole, 50.0, 0.0).relative == pytest.approx(1.0)


def test_relative_illumination_of_a_thin_lens_with_a_small_stop_follows_cos4():
    """A thin lens (f ~ 100) with a small stop just in front of it and no other vignetting, focused at infinity:
    the illumination falls off as cos^4 of the field angle, up to the lens's small distortion of the pupil."""
    lens = [(0.0, 0.2, 1.0, 4.0), (100.0, 2.0, 1.5, 12.0), (-100.0, 0.0, 1.0, 12.0)]
    cp = rl.cardinal_points(lens)
    radii = np.array([10.0, 30.0, 45.0, 58.0])  # up to a 30-degree field angle
    angles = np.array([rl.chief_ray_angle(lens, cp.z_rear_focal, r) for r in radii])
    assert math.degrees(angles[-1]) == pytest.approx(30.0, abs=0.5)
    np.testing.assert_allclose(np.tan(angles), radii / cp.efl, rtol=0.02)  # nearly distortion-free
    ill = rl.relative_illumination(lens, cp.z_rear_focal, radii)
    np.testing.assert_allclose(ill.relative, np.cos(angles) ** 4, rtol=0.03)
    assert np.all(np.diff(ill.relative) < 0.0)


def test_relative_illumination_is_deterministic():
    a = rl.relative_illumination(TRIPLET, rl.default_sensor_z(TRIPLET), [5.0, 15.0], n_rays=20_000)
    b = rl.relative_illumination(TRIPLET, rl.default_sensor_z(TRIPLET), [5.0, 15.0], n_rays=20_000)
    np.testing.assert_array_equal(a.irradiance, b.irradiance)


def test_the_chief_ray_passes_through_the_centre_of_the_stop():
    z_sensor = rl.default_sensor_z(TRIPLET)
    stop = rl.stop_index(TRIPLET)
    for r in (3.0, 12.0, -12.0):
        ray = rl.chief_ray(TRIPLET, z_sensor, r)
        # Trace it back from the scene through the surfaces up to the stop (the same vertex positions).
        start = ray.origin + 10.0 * ray.direction
        p, _, ok = rl.trace(TRIPLET[: stop + 1], start, -ray.direction, from_sensor=False, apertures=False)
        assert ok
        assert p[2] == pytest.approx(rl.vertex_z(TRIPLET)[stop], abs=1e-12)
        assert abs(p[0]) < 1e-9 and abs(p[1]) < 1e-12
    assert rl.chief_ray_angle(TRIPLET, z_sensor, -12.0) == pytest.approx(
        rl.chief_ray_angle(TRIPLET, z_sensor, 12.0), rel=1e-9)


def test_dispersed_ior_reproduces_n_d_and_the_abbe_number():
    n_d = rl.dispersed_ior(BK7_ND, BK7_VD, rl.LAMBDA_D_NM)
    n_f = rl.dispersed_ior(BK7_ND, BK7_VD, rl.LAMBDA_F_NM)
    n_c = rl.dispersed_ior(BK7_ND, BK7_VD, rl.LAMBDA_C_NM)
    assert n_d == pytest.approx(BK7_ND, abs=1e-14)
    assert n_f - n_c == pytest.approx((BK7_ND - 1.0) / BK7_VD, rel=1e-12)
    # Normal dispersion: the index falls with wavelength; for N-BK7 the Cauchy fit is within ~1e-3 of the catalogue
    # (n_F = 1.52238, n_C = 1.51432).
    n = rl.dispersed_ior(BK7_ND, BK7_VD, np.array([400.0, 500.0, 600.0, 700.0]))
    assert np.all(np.diff(n) < 0.0)
    assert n_f == pytest.approx(1.52238, abs=1e-3) and n_c == pytest.approx(1.51432, abs=1e-3)
    assert rl.dispersed_ior(1.0, math.inf, 450.0) == 1.0


def test_a_thin_lens_shows_longitudinal_chromatic_aberration_of_one_over_v():
    """Per-wavelength indices through the override: each focal length follows the lensmaker's formula with n(lambda),
    and for a thin lens f_d (1/f_F - 1/f_C) = 1/V."""
    surfaces = [(0.0, 1.0, 1.0, 10.0), (100.0, 1.0, BK7_ND, 30.0), (-100.0, 90.0, 1.0, 30.0)]
    f = {}
    for name, lam in (("d", rl.LAMBDA_D_NM), ("F", rl.LAMBDA_F_NM), ("C", rl.LAMBDA_C_NM)):
        n = rl.dispersed_ior(BK7_ND, BK7_VD, lam)
        f[name] = rl.paraxial_focal_length(surfaces, [None, n, None])
        assert f[name] == pytest.approx(thick_lens(n, 100.0, -100.0, 1.0)[0], rel=1e-8)
    assert f["d"] * (1.0 / f["F"] - 1.0 / f["C"]) == pytest.approx(1.0 / BK7_VD, rel=0.01)
    assert f["F"] < f["d"] < f["C"]  # blue focuses nearer
