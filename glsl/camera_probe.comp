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
// Out, two vec4 per item: (origin, weight), (direction, 0).
layout(std430, binding = PROBE_OUT_BINDING) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform int item_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= item_count) return;
    vec4 item = probe_in[i];
    float weight;
    Ray ray = camera_ray(item.xy, item.zw, weight);
    probe_out[2 * i] = vec4(ray.o, weight);
    probe_out[2 * i + 1] = vec4(ray.d, 0.0);
}
