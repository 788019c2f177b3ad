// NormalMap (scene/materials/normal_map.py): a tangent-space normal map gives the shading normal of the
// material it holds; resolve_material (glsl/bsdf.glsl) applies mapped_normal on the way down. Included by
// glsl/bsdf.glsl through the generated dispatch (scene/materials/registry.py).

// Mitsuba's normalmap: the texture's (2 rgb - 1) in the shading frame whose tangent follows dp/du.
vec3 mapped_normal(SurfaceHit s, vec3 n, int texture) {
    vec3 dpdu, dpdv;
    surface_tangents(s, n, dpdu, dpdv);
    vec3 t = dpdu - n * dot(n, dpdu);
    t = dot(t, t) > 0.0 ? normalize(t) : frame_around(n)[0];
    vec3 c = 2.0 * texture_rgb(texture, s.uv) - 1.0;
    vec3 mapped = c.x * t + c.y * cross(n, t) + c.z * n;
    return dot(mapped, mapped) > 0.0 ? normalize(mapped) : n;
}
