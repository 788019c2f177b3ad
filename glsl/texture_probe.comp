#version 430
// Looks textures up directly, for tests: texture_rgb(t, uv) for each item, as a surface hit would.
// Not used while rendering.

layout(local_size_x = LOCAL_SIZE_X) in;

#include "common.glsl"
#include "textures.glsl"

// In, one vec4 per item: (u, v, texture record, -). Out, one vec4 per item: (rgb, -).
layout(std430, binding = PROBE_IN_BINDING) readonly buffer ProbeIn { vec4 probe_in[]; };
layout(std430, binding = PROBE_OUT_BINDING) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform int item_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= item_count) return;
    vec4 item = probe_in[i];
    probe_out[i] = vec4(texture_rgb(int(item.z), item.xy), 0.0);
}
