"""The exit-pupil search's inner loop in compiled code (numba): which rays from film points to points on the rear
vertex's plane get out through the lens.

lens_system.LensSetting.pupil_bounds traces tens of thousands of rays per table, once per focus and f-number:
the numpy tracer's temporaries cost most of a second there, this loop a few milliseconds. It is the same optics
as lens_system's tracer (the sphere's crossing on the vertex's side, Snell's law, clear apertures), with the
stop taken as the circle round its opening: the table only has to hold every ray that can get through.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _gets_out(ox, oy, oz, dx, dy, dz, vertex_z, radius, aperture_radius, ior, stop_radius):
    """Whether the ray (o, d) from the sensor gets out of the front of the lens with these indices."""
    for k in range(len(radius) - 1, -1, -1):
        r = radius[k]
        if r == 0.0:
            t = (vertex_z[k] - oz) / dz
            ox, oy, oz = ox + t * dx, oy + t * dy, vertex_z[k]
            if t <= 0.0 or ox * ox + oy * oy > stop_radius * stop_radius:
                return False
            continue
        cz = vertex_z[k] + r
        px, py, pz = ox, oy, oz - cz
        b = px * dx + py * dy + pz * dz
        c = px * px + py * py + pz * pz - r * r
        disc = b * b - c
        if disc < 0.0:
            return False
        root = math.sqrt(disc)
        t = -b - root if (dz > 0.0) == (r > 0.0) else -b + root
        if t <= 0.0:
            return False
        ox, oy, oz = ox + t * dx, oy + t * dy, oz + t * dz
        if ox * ox + oy * oy > aperture_radius[k] * aperture_radius[k]:
            return False
        nx, ny, nz = ox / r, oy / r, (oz - cz) / r
        if nx * dx + ny * dy + nz * dz > 0.0:
            nx, ny, nz = -nx, -ny, -nz
        eta = ior[k] / (1.0 if k == 0 else ior[k - 1])
        cos_in = -(nx * dx + ny * dy + nz * dz)
        sin2_out = eta * eta * max(0.0, 1.0 - cos_in * cos_in)
        if sin2_out > 1.0:
            return False
        scale = eta * cos_in - math.sqrt(1.0 - sin2_out)
        dx, dy, dz = eta * dx + scale * nx, eta * dy + scale * ny, eta * dz + scale * nz
    return True


@njit(cache=True)
def rays_through(film_x, rear_x, rear_y, sensor_z, vertex_z, radius, aperture_radius, iors, stop_radius):
    """For every film point (film_x[i], 0, sensor_z) and every rear-plane point (rear_x[j], rear_y[j],
    vertex_z[-1]): whether the ray between them gets out of the front of the lens at any of the wavelengths whose
    indices are the rows of ``iors`` (channels, surfaces; ``iors[c, k]`` the medium behind surface k). Returns
    (len(film_x), len(rear_x)) booleans."""
    count = len(radius)
    passed = np.zeros((len(film_x), len(rear_x)), np.bool_)
    for i in range(len(film_x)):
        for j in range(len(rear_x)):
            ox, oz = film_x[i], sensor_z
            dx, dy, dz = rear_x[j] - ox, rear_y[j], vertex_z[count - 1] - oz
            norm = math.sqrt(dx * dx + dy * dy + dz * dz)
            for c in range(iors.shape[0]):
                if _gets_out(ox, 0.0, oz, dx / norm, dy / norm, dz / norm, vertex_z, radius, aperture_radius,
                             iors[c], stop_radius):
                    passed[i, j] = True
                    break
    return passed
