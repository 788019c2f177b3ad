#version 430
// Ray queries on the same kd-tree the renderer traverses: nearest hit of each ray in a batch.
// Used for click-to-focus, for picking objects in the viewport, and to test the traversal against brute force.

layout(local_size_x = LOCAL_SIZE_X) in;

#include "common.glsl"
#include "intersect.glsl"
#include "bsp.glsl"

// In: two vec4 per ray, (origin, t_min), (direction, t_max). Out: two vec4 per ray, (t, primitive as float bits,
// b1, b2) and (instance as float bits, -, -, -): the instance whose mesh group holds the primitive, or -1.
layout(std430, binding = RAYS_BINDING) readonly buffer Rays { vec4 rays[]; };
layout(std430, binding = HITS_BINDING) writeonly buffer Hits { vec4 hits[]; };

uniform int ray_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= ray_count) return;
    vec4 a = rays[2 * i], b = rays[2 * i + 1];
    Hit hit;
    bool found = trace_scene(Ray(a.xyz, b.xyz), a.w, b.w, false, hit);
    hits[2 * i] = found ? vec4(hit.t, intBitsToFloat(hit.prim), hit.uv) : vec4(INFINITY, intBitsToFloat(NO_HIT), 0.0, 0.0);
    hits[2 * i + 1] = vec4(intBitsToFloat(found ? hit.instance : NO_INSTANCE), 0.0, 0.0, 0.0);
}
