// Diffuse (scene/materials/diffuse.py): Lambertian reflection, b.color / pi.
// Included by glsl/bsdf.glsl through the generated dispatch (scene/materials/registry.py).

vec3 diffuse_eval(Bsdf b, vec3 wo, vec3 wi, bool same_side, inout float pdf) {
    if (!same_side || wi.z <= 0.0) return vec3(0.0);
    pdf = wi.z * INV_PI;
    return b.color * INV_PI * wi.z;
}

int diffuse_sample(SurfaceHit s, Bsdf b, vec3 u, vec3 wo, inout vec3 wi, inout bool transmit, inout vec3 wi_world,
                   inout vec3 weight, inout float pdf, inout bool delta) {
    wi = sample_cosine_hemisphere(u.xy);
    pdf = wi.z * INV_PI;
    weight = b.color;
    return BSDF_SAMPLE_CONTINUE;
}
