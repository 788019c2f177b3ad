// Conductor (scene/materials/conductor.py): Fresnel reflection with a complex index, smooth (a Dirac lobe) or
// microfacet-rough. Included by glsl/bsdf.glsl through the generated dispatch (scene/materials/registry.py).

vec3 conductor_eval(Bsdf b, vec3 wo, vec3 wi, bool same_side, inout float pdf) {
    if (!same_side || wi.z <= 0.0) return vec3(0.0);
    vec3 m = normalize(wo + wi);
    pdf = microfacet_pdf(wo, m, b.alpha, b.beckmann) / (4.0 * dot(wo, m));
    vec3 f = fresnel_conductor(dot(wo, m), b.eta3, b.k);
    return b.tint * f * (microfacet_d(m, b.alpha, b.beckmann) * microfacet_g(wo, wi, b.alpha, b.beckmann) / (4.0 * wo.z));
}

int conductor_sample(SurfaceHit s, Bsdf b, vec3 u, vec3 wo, inout vec3 wi, inout bool transmit, inout vec3 wi_world,
                     inout vec3 weight, inout float pdf, inout bool delta) {
    vec3 m = b.alpha == 0.0 ? vec3(0.0, 0.0, 1.0) : microfacet_sample(wo, b.alpha, b.beckmann, u.xy);
    wi = 2.0 * dot(wo, m) * m - wo;
    if (wi.z <= 0.0) return BSDF_SAMPLE_FAILED;
    vec3 f = b.tint * fresnel_conductor(dot(wo, m), b.eta3, b.k);
    if (b.alpha == 0.0) {
        delta = true;
        pdf = 1.0;
        weight = f;
    } else {
        pdf = microfacet_pdf(wo, m, b.alpha, b.beckmann) / (4.0 * dot(wo, m));
        weight = f * microfacet_reflection_weight(wo, wi, m, b.alpha, b.beckmann);
    }
    return BSDF_SAMPLE_CONTINUE;
}
