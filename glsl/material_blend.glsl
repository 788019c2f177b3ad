// Blend (scene/materials/blend.py): resolve_material (glsl/bsdf.glsl) picks one of the two records it holds
// with the blend's odds, with a number from the hit itself. Included by glsl/bsdf.glsl through the generated
// dispatch (scene/materials/registry.py).

// A number in [0, 1) from the hit itself, so that choosing within a blend takes no dimension of the sampler.
float hit_hash(SurfaceHit s, int level) {
    return hash_unit(s.p, s.wo.xy, floatBitsToUint(s.wo.z) + uint(level));
}
