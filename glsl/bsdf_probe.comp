#version 430
// Calls the BSDF code directly, for tests: at a surface with normal +Z, for each item either sample a
// direction (mode 0) or evaluate a given one (mode 1). Not used while rendering.

layout(local_size_x = LOCAL_SIZE_X) in;

#include "common.glsl"
#include "sampling.glsl"
#include "surface.glsl"
#include "textures.glsl"
#include "microfacet.glsl"
#include "bsdf.glsl"

// In, two vec4 per item: (wo, front face), (u0, u1, u2, mode) in sample mode or (wi, mode) in eval mode.
layout(std430, binding = PROBE_IN_BINDING) readonly buffer ProbeIn { vec4 probe_in[]; };
// Out, two vec4 per item: (wi, pdf), (weight or f|cos|, delta or success).
layout(std430, binding = PROBE_OUT_BINDING) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform int item_count;
uniform int probe_material;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= item_count) return;
    vec4 a = probe_in[2 * i], b = probe_in[2 * i + 1];
    SurfaceHit s;
    s.p = vec3(0.0);
    s.front_face = a.w > 0.5;
    s.ng = vec3(0.0, 0.0, 1.0);
    s.ns = s.ng;
    s.wo = normalize(a.xyz);
    s.uv = vec2(0.5);
    s.material = probe_material;
    s.prim = 0;
    s.instance = NO_INSTANCE;
    if (b.w < 0.5) {
        vec3 wi, weight;
        float pdf;
        bool delta;
        bool ok = bsdf_sample(s, bsdf_at(s), b.xyz, wi, weight, pdf, delta);
        probe_out[2 * i] = vec4(ok ? wi : vec3(0.0), ok ? pdf : 0.0);
        probe_out[2 * i + 1] = vec4(ok ? weight : vec3(0.0), ok ? (delta ? 2.0 : 1.0) : 0.0);
    } else {
        float pdf;
        vec3 f = bsdf_eval(s, bsdf_at(s), normalize(b.xyz), pdf);
        probe_out[2 * i] = vec4(normalize(b.xyz), pdf);
        probe_out[2 * i + 1] = vec4(f, 1.0);
    }
}
