// The thin-lens camera (docs/architecture.md, "The camera"). Mirrors the host's
// CameraFrame.rays (app/lenslab/scene/camera.py); glsl/camera_probe.comp and tests/test_camera_rays.py compare them.
//
// The camera looks down its local -Z. A pinhole ray through the image point (x, y) has the direction
// (x tan(fov_x/2), y tan(fov_y/2), -1), so it meets the plane of focus z = -focus_distance at that direction
// times focus_distance: the plane of focus is a plane, not a sphere. A thin-lens ray starts at a point
// sampled uniformly on the aperture (a disk of radius f/2N, or a regular polygon for bladed apertures) and
// passes through that same point of focus.

uniform vec3 cam_position;
uniform mat3 cam_to_world;     // columns: right, up, back
uniform vec2 cam_tan_half_fov; // tan(fov_x / 2), tan(fov_y / 2)
uniform float cam_lens_radius; // metres
uniform float cam_focus_distance;
uniform int cam_blades;        // 0: round aperture
uniform float cam_blade_rotation;
uniform ivec2 image_size;

// pixel_sample: continuous pixel coordinates, (0,0) at the top-left corner of the image.
Ray camera_ray(vec2 pixel_sample, vec2 u_lens) {
    vec2 ndc = vec2(2.0 * pixel_sample.x / float(image_size.x) - 1.0,
                    1.0 - 2.0 * pixel_sample.y / float(image_size.y));
    vec3 pinhole_dir = vec3(ndc * cam_tan_half_fov, -1.0);
    vec3 focus_point = pinhole_dir * cam_focus_distance;
    vec2 lens = cam_blades >= 3 ? sample_polygon(u_lens, cam_blades, cam_blade_rotation)
                                : sample_concentric_disk(u_lens);
    vec3 origin = vec3(cam_lens_radius * lens, 0.0);
    Ray ray;
    ray.o = cam_position + cam_to_world * origin;
    ray.d = normalize(cam_to_world * (focus_point - origin));
    return ray;
}
