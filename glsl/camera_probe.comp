#version 430
// Calls camera_ray() directly, for tests: for each item, the ray through a pixel sample and a lens sample.
// tests/test_camera_rays.py compares these rays with the Python camera's (lenslab.scene.camera.CameraFrame),
// so the shader and the host can never disagree on where a pixel looks. Not used while rendering.

layout(local_size_x = LOCAL_SIZE_X) in;

#include "common.glsl"
#include "sampling.glsl"
#include "camera.glsl"

// In, one vec4 per item: (pixel x, pixel y, lens u, lens v), pixels as in camera_ray().
layout(std430, binding = PROBE_IN_BINDING) readonly buffer ProbeIn { vec4 probe_in[]; };
// Out, three vec4 per item: (origin, red weight), (direction, green weight), (blue weight, 0, 0, 0).
layout(std430, binding = PROBE_OUT_BINDING) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform int item_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= item_count) return;
    vec4 item = probe_in[i];
    vec3 weight;
    Ray ray = camera_ray(item.xy, item.zw, weight);
    probe_out[3 * i] = vec4(ray.o, weight.r);
    probe_out[3 * i + 1] = vec4(ray.d, weight.g);
    probe_out[3 * i + 2] = vec4(weight.b, 0.0, 0.0, 0.0);
}
