// A real lens, traced through its glass (docs/lenses.md; Kolb, Mitchell and Hanrahan 1995; pbrt-v4's
// RealisticCamera). Mirrors LensSetting.rays (app/lenslab/optics/lens_system.py) step by step;
// tests/test_real_lens.py runs both on the same numbers. Included by camera.glsl, after the aperture's functions.
//
// Lengths in mm, in the camera's frame (it looks down -z): the sensor at z = lens_sensor_z, surfaces from the
// front element (index 0) to the rear. A ray starts on the sensor, aims at a point of the exit pupil's box for its
// distance from the centre (a box or a disk, precomputed, turned to its direction: the lens is round), and is refracted surface by
// surface towards the front; it is lost where it misses a sphere, lands outside a clear aperture or the stop, or is
// totally reflected. Its weight is the camera measurement's cos^4(theta) dA / d^2 over the box, divided by what an
// ideal lens at the same f-number gives (lens_weight_scale holds 1 / (d^2 * pi / (4 N^2))).

uniform int lens_surface_count;   // 0: the thin lens
uniform vec4 lens_surfaces[MAX_LENS_SURFACES];  // (radius of curvature, 0 for the stop; vertex z; clear radius; -)
uniform vec3 lens_iors[MAX_LENS_SURFACES];      // the medium behind each surface at each channel's wavelength
uniform int lens_dispersive;      // 1: each sample is traced at one channel's wavelength
uniform float lens_stop_radius;   // mm: the round stop at this f-number (a bladed stop's shape is scaled from it)
uniform float lens_sensor_z;
uniform float lens_rear_z;        // the rear vertex's plane, where the pupil boxes lie
uniform vec2 lens_film_half;      // half the film's width and height, mm
uniform float lens_film_radius;   // how far from the centre the pupil table reaches, mm
uniform float lens_weight_scale;
uniform vec4 lens_pupil[PUPIL_BINS];  // per radial bin, the exit pupil's box (x0, y0, x1, y1) for a point on +x
uniform vec4 lens_pupil_disk[PUPIL_BINS];  // and the disk round it (centre, radius; w = 1: sample the disk)

// Whether a point on the stop's plane (mm from the axis) is inside the iris: round, straight or rounded blades
// (Aperture.contains, in units of the round stop's radius).
bool inside_stop(vec2 p) {
    p /= lens_stop_radius * cam_aperture_axes;
    float r = length(p);
    if (cam_aperture_kind != APERTURE_BLADES && cam_aperture_kind != APERTURE_ROUNDED_BLADES) return r <= 1.0;
    float wedge = 2.0 * PI / float(cam_blades);
    float angle = mod(atan(p.y, p.x) - cam_blade_rotation, wedge);
    if (angle < 0.0) angle += wedge;
    float edge = cam_aperture_kind == APERTURE_ROUNDED_BLADES ? rounded_blade_radius(angle)
                                                               : cos(PI / float(cam_blades)) / cos(angle - PI / float(cam_blades));
    return r <= edge;
}

// Where a ray (o, d) meets surface k: the part of its sphere on the vertex's side. False if it misses.
bool lens_surface_hit(int k, vec3 o, vec3 d, out vec3 p, out vec3 normal) {
    float radius = lens_surfaces[k].x, vertex = lens_surfaces[k].y;
    if (radius == 0.0) {
        float t = (vertex - o.z) / d.z;
        p = o + t * d;
        normal = vec3(0.0, 0.0, 1.0);
        return t > 0.0;
    }
    vec3 oc = o - vec3(0.0, 0.0, vertex + radius);
    float b = dot(oc, d), c = dot(oc, oc) - radius * radius;
    float disc = b * b - c;
    if (disc < 0.0) return false;
    float root = sqrt(disc);
    float t = ((d.z > 0.0) == (radius > 0.0)) ? -b - root : -b + root;
    if (t <= 0.0) return false;
    p = o + t * d;
    normal = (oc + t * d) / radius;
    if (dot(normal, d) > 0.0) normal = -normal;
    return true;
}

// Out through the lens from the sensor; `channel` picks the wavelength's indices. False if the ray is lost.
bool trace_lens_from_film(inout vec3 o, inout vec3 d, int channel) {
    for (int k = lens_surface_count - 1; k >= 0; k--) {
        vec3 p, normal;
        if (!lens_surface_hit(k, o, d, p, normal)) return false;
        o = p;
        if (lens_surfaces[k].x == 0.0) {
            if (!inside_stop(p.xy)) return false;
            continue;
        }
        float clear = lens_surfaces[k].z;
        if (dot(p.xy, p.xy) > clear * clear) return false;
        float eta = lens_iors[k][channel] / (k == 0 ? 1.0 : lens_iors[k - 1][channel]);
        float cos_in = -dot(normal, d);
        float sin2_out = eta * eta * max(0.0, 1.0 - cos_in * cos_in);
        if (sin2_out > 1.0) return false;  // totally reflected inside the glass
        d = eta * d + (eta * cos_in - sqrt(1.0 - sin2_out)) * normal;
    }
    return true;
}

// A camera ray through the real lens: the camera's frame, mm; `weight` its colour weight (0 if lost).
Ray real_lens_ray(vec2 ndc, vec2 u, out vec3 weight) {
    vec3 colour = vec3(1.0);
    int channel = 1;
    if (lens_dispersive != 0) {  // one channel's wavelength, chosen by a third of u.x; the rest of u.x goes on
        float chosen = min(floor(3.0 * u.x), 2.0);
        u.x = 3.0 * u.x - chosen;
        channel = int(chosen);
        colour = vec3(0.0);
        colour[channel] = 3.0;
    }
    vec3 film = vec3(-ndc * lens_film_half, lens_sensor_z);  // the lens turns the image round
    float r = length(film.xy);
    int bin = min(int(r / lens_film_radius * float(PUPIL_BINS)), PUPIL_BINS - 1);
    vec4 box = lens_pupil[bin], disk = lens_pupil_disk[bin];
    float area;
    vec2 q;
    if (disk.w > 0.0) {  // a round pupil: its disk wastes fewer samples than its box
        area = PI * disk.z * disk.z;
        q = disk.xy + disk.z * sample_concentric_disk(u);
    } else {
        area = (box.z - box.x) * (box.w - box.y);
        q = box.xy + u * (box.zw - box.xy);
    }
    vec2 along = r > 0.0 ? film.xy / r : vec2(1.0, 0.0);
    vec3 target = vec3(along.x * q.x - along.y * q.y, along.y * q.x + along.x * q.y, lens_rear_z);
    vec3 d = normalize(target - film);
    Ray ray;
    ray.o = film;
    ray.d = d;
    float cos_theta = -d.z;
    weight = vec3(0.0);
    if (area > 0.0 && trace_lens_from_film(ray.o, ray.d, channel)) {
        float c2 = cos_theta * cos_theta;
        weight = colour * (c2 * c2 * area * lens_weight_scale);
    }
    return ray;
}
