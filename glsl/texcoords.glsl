// Texture coordinates of a point on a primitive: for shading (surface.glsl) and for the cut-out test that
// traversal makes (mask.glsl).

// A sphere's (u, v) at unit direction n from its centre: longitude from +X towards +Z, v = 0 at the top.
vec2 sphere_uv(vec3 n) {
    return vec2(atan(n.z, n.x) * (0.5 * INV_PI) + 0.5, acos(clamp(n.y, -1.0, 1.0)) * INV_PI);
}

// A triangle's (u, v) at barycentrics (b1, b2), from its corners' in the shading buffer (common.glsl).
vec2 triangle_uv(int prim, vec2 bary) {
    int j = SHADING_ROWS * prim;
    vec4 s0 = shading[j], s1 = shading[j + 1], s2 = shading[j + 2], s3 = shading[j + 3];
    return (1.0 - bary.x - bary.y) * vec2(s0.w, s1.w) + bary.x * vec2(s2.w, s3.x) + bary.y * s3.yz;
}
