// The thin-lens camera (docs/architecture.md, "The camera"), and the real lens's dispatch (real_lens.glsl). Mirrors the host's
// CameraFrame.rays (app/lenslab/scene/camera.py); glsl/camera_probe.comp and tests/test_camera_rays.py compare them.
//
// The camera looks down its local -Z. A pinhole ray through the image point (x, y) has the direction
// (x tan(fov_x/2), y tan(fov_y/2), -1), so it meets the plane of focus z = -focus_distance at that direction
// times focus_distance: the plane of focus is a plane, not a sphere. A thin-lens ray starts at a point
// sampled on the aperture (app/lenslab/optics/aperture.py: round, straight or rounded blades, or an image;
// squeezed for anamorphic bokeh) and passes through that same point of focus. The sensor's distance and the
// sensor fit are folded into tan(fov/2) by the host.

uniform vec3 cam_position;
uniform mat3 cam_to_world;     // columns: right, up, back
uniform vec2 cam_tan_half_fov; // tan(fov_x / 2), tan(fov_y / 2)
uniform float cam_lens_radius; // metres: the round f/N stop's radius, the aperture's unit
uniform float cam_focus_distance;
uniform int cam_aperture_kind; // APERTURE_ROUND, APERTURE_BLADES, APERTURE_ROUNDED_BLADES or APERTURE_IMAGE
uniform int cam_blades;
uniform float cam_blade_rotation;
uniform vec2 cam_blade_arc;       // rounded blades: distance to each edge's arc centre, the arc's radius
uniform float cam_blade_wedge_area; // rounded blades: area of one blade's wedge, unit corners' circle
uniform vec2 cam_aperture_axes;   // the shape's horizontal and vertical scale (size and squeeze)
uniform vec2 cam_barrel_gain;     // the barrel opening's shift per unit of image x and y (0: no clipping)
uniform float cam_barrel_radius;
uniform ivec2 cam_aperture_image_size; // columns, rows of an aperture image
uniform sampler2D aperture_table; // CameraFrame's Aperture.table: cumulative distributions, one per row
uniform ivec2 image_size;

float aperture_cdf(int row, int i) { return texelFetch(aperture_table, ivec2(i, row), 0).r; }

// The bin i in [0, count) of a table row with cdf[i] <= u < cdf[i + 1] (aperture.py's find_interval).
int find_interval(int row, int count, float u) {
    int low = 0, high = count;  // invariant: cdf[low] <= u (cdf[0] = 0), and u < cdf[high] unless high = count
    while (high - low > 1) {
        int middle = (low + high) / 2;
        if (aperture_cdf(row, middle) <= u) low = middle; else high = middle;
    }
    return low;
}

// Rounded blades: the edge of one blade's wedge at `angle` from its first corner (unit corners' circle).
float rounded_blade_radius(float angle) {
    float centre = cam_blade_arc.x, radius = cam_blade_arc.y;
    float towards_arc = centre * cos(angle - PI / float(cam_blades));
    return towards_arc + sqrt(towards_arc * towards_arc - centre * centre + radius * radius);
}

// A point on the unit-scale shape and the sample's weight (Aperture.sample, before the axes are applied).
vec2 sample_rounded_blades(vec2 u, out float weight) {
    float n = float(cam_blades);
    float k = min(floor(u.x * n), n - 1.0);
    float v = u.x * n - k;
    int i = find_interval(0, ROUNDED_BLADE_BINS, v);
    float below = aperture_cdf(0, i);
    float bin_mass = aperture_cdf(0, i + 1) - below;
    float wedge = 2.0 * PI / n;
    float bin_width = wedge / float(ROUNDED_BLADE_BINS);
    float angle = (float(i) + (v - below) / bin_mass) * bin_width;
    float edge = rounded_blade_radius(angle);
    weight = (0.5 * edge * edge / cam_blade_wedge_area) / (bin_mass / bin_width);
    float theta = cam_blade_rotation + k * wedge + angle;
    return edge * sqrt(u.y) * vec2(cos(theta), sin(theta));
}

vec2 sample_aperture_image(vec2 u) {
    int cols = cam_aperture_image_size.x, rows = cam_aperture_image_size.y;
    int row = find_interval(rows, rows, u.y);
    float below = aperture_cdf(rows, row);
    float y = float(row) + (u.y - below) / (aperture_cdf(rows, row + 1) - below);
    int col = find_interval(row, cols, u.x);
    below = aperture_cdf(row, col);
    float x = float(col) + (u.x - below) / (aperture_cdf(row, col + 1) - below);
    return vec2(2.0 * x / float(cols) - 1.0, 1.0 - 2.0 * y / float(rows));
}

#include "real_lens.glsl"

// pixel_sample: continuous pixel coordinates, (0,0) at the top-left corner of the image. `colour_weight`: 0 where
// the barrel or the glass blocks the ray, else the aperture sample's weight (1 but for rounded blades and a real
// lens), per colour channel (a dispersive real lens traces each sample at one channel's wavelength).
Ray camera_ray(vec2 pixel_sample, vec2 u_lens, out vec3 colour_weight) {
    vec2 ndc = vec2(2.0 * pixel_sample.x / float(image_size.x) - 1.0,
                    1.0 - 2.0 * pixel_sample.y / float(image_size.y));
    if (lens_surface_count > 0) {  // traced through the glass, in the camera's frame (mm), then to the world
        Ray local = real_lens_ray(ndc, u_lens, colour_weight);
        Ray ray;
        ray.o = cam_position + cam_to_world * (local.o * 0.001);
        ray.d = normalize(cam_to_world * local.d);
        return ray;
    }
    vec3 pinhole_dir = vec3(ndc * cam_tan_half_fov, -1.0);
    vec3 focus_point = pinhole_dir * cam_focus_distance;
    float weight = 1.0;
    vec2 lens;
    if (cam_aperture_kind == APERTURE_BLADES) lens = sample_polygon(u_lens, cam_blades, cam_blade_rotation);
    else if (cam_aperture_kind == APERTURE_ROUNDED_BLADES) lens = sample_rounded_blades(u_lens, weight);
    else if (cam_aperture_kind == APERTURE_IMAGE) lens = sample_aperture_image(u_lens);
    else lens = sample_concentric_disk(u_lens);
    lens *= cam_aperture_axes;
    if (cam_barrel_radius > 0.0 && length(lens - ndc * cam_barrel_gain) > cam_barrel_radius) weight = 0.0;
    vec3 origin = vec3(cam_lens_radius * lens, 0.0);
    Ray ray;
    ray.o = cam_position + cam_to_world * origin;
    ray.d = normalize(cam_to_world * (focus_point - origin));
    colour_weight = vec3(weight);
    return ray;
}
