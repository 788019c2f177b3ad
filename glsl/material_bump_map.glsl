// BumpMap (scene/materials/bump_map.py): a height texture tilts the shading normal of the material it holds;
// resolve_material (glsl/bsdf.glsl) applies bumped_normal on the way down. Included by glsl/bsdf.glsl through
// the generated dispatch (scene/materials/registry.py).

// d value / d(u, v) by differences over a step small against a texel: within a texel that is the bilinear
// filter's exact slope. The step grows with |uv| so that float spacing never swamps it. Three lookups in a
// loop rather than unrolled calls: each inlined lookup is a large piece of a kernel llvmpipe must compile.
// A checkerboard's value, and a nearest-filtered image's, is flat but for its edges, whose slope is
// infinite: zero, as Mitsuba's eval_1_grad.
vec2 texture_value_gradient(int t, vec2 uv) {
    vec4 r0 = materials[texture_base + TEXTURE_ROWS * t], r3 = materials[texture_base + TEXTURE_ROWS * t + 3];
    if (int(r0.x) == TEXTURE_CHECKER || int(r3.z) == TEXTURE_FILTER_NEAREST) return vec2(0.0);
    float h = max(6.1e-5, 1.2e-4 * max(abs(uv.x), abs(uv.y)));
    vec3 values;
    for (int i = 0; i < 3; i++) values[i] = texture_value(t, uv + h * vec2(i == 1, i == 2));
    return (values.yz - values.x) / h;
}

// Mitsuba's bumpmap: the surface moves by the height h(u, v) along the normal, so its tangents gain the
// height's slopes: dp/du' = dp/du projected onto the tangent plane + n dh/du (likewise v), n' = dp/du' x dp/dv',
// on the side of the geometric normal. All in the front face's orientation.
vec3 bumped_normal(SurfaceHit s, vec3 n, vec3 ng, int texture, float scale) {
    vec3 dpdu, dpdv;
    surface_tangents(s, n, dpdu, dpdv);
    vec2 slope = scale * texture_value_gradient(texture, s.uv);
    vec3 du = dpdu + n * (slope.x - dot(n, dpdu));
    vec3 dv = dpdv + n * (slope.y - dot(n, dpdv));
    vec3 bumped = cross(du, dv);
    if (dot(bumped, bumped) <= 0.0) return n;
    bumped = normalize(bumped);
    return dot(bumped, ng) < 0.0 ? -bumped : bumped;
}
