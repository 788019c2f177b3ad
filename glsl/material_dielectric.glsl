// Dielectric (scene/materials/dielectric.py): Fresnel reflection and Snell refraction, smooth (Dirac lobes)
// or rough. Included by glsl/bsdf.glsl through the generated dispatch (scene/materials/registry.py).

// -- rough dielectric (Walter et al. 2007, as pbrt-v4's DielectricBxDF) -----------------------------------
vec3 rough_dielectric_eval(Bsdf b, vec3 wo, vec3 wi, out float pdf) {
    pdf = 0.0;
    bool reflect = wi.z > 0.0;
    vec3 m = reflect ? normalize(wo + wi) : normalize(wi * b.eta + wo);
    if (m.z < 0.0) m = -m;
    if (dot(m, wi) * wi.z < 0.0 || dot(m, wo) * wo.z < 0.0) return vec3(0.0);  // back-facing microfacet
    float f = fresnel_dielectric(dot(wo, m), b.eta);
    float vis_pdf = microfacet_pdf(wo, m, b.alpha, b.beckmann);
    float d = microfacet_d(m, b.alpha, b.beckmann), g = microfacet_g(wo, wi, b.alpha, b.beckmann);
    if (reflect) {
        pdf = vis_pdf / (4.0 * abs(dot(wo, m))) * f;
        return b.tint * (d * g * f / (4.0 * wo.z));
    }
    float denom = dot(wi, m) + dot(wo, m) / b.eta;
    denom *= denom;
    if (denom == 0.0) return vec3(0.0);
    float dm_dwi = abs(dot(wi, m)) / denom;
    pdf = vis_pdf * dm_dwi * (1.0 - f);
    float ft = (1.0 - f) * d * g * abs(dot(wi, m) * dot(wo, m) / (wo.z * denom));
    return b.tint * (ft / (b.eta * b.eta));  // radiance is compressed entering denser media: 1/eta^2
}

vec3 dielectric_eval(Bsdf b, vec3 wo, vec3 wi, bool same_side, inout float pdf) {
    if (same_side != (wi.z > 0.0)) return vec3(0.0);
    return rough_dielectric_eval(b, wo, wi, pdf);
}

int dielectric_sample(SurfaceHit s, Bsdf b, vec3 u, vec3 wo, inout vec3 wi, inout bool transmit, inout vec3 wi_world,
                      inout vec3 weight, inout float pdf, inout bool delta) {
    vec3 m = b.alpha == 0.0 ? vec3(0.0, 0.0, 1.0) : microfacet_sample(wo, b.alpha, b.beckmann, u.xy);
    float f = fresnel_dielectric(dot(wo, m), b.eta);
    if (u.z < f) {
        wi = 2.0 * dot(wo, m) * m - wo;
        if (wi.z <= 0.0) return BSDF_SAMPLE_FAILED;
    } else {
        if (!refract_dir(wo, m, b.eta, wi) || wi.z >= 0.0) return BSDF_SAMPLE_FAILED;
        transmit = true;
    }
    if (b.alpha == 0.0) {
        delta = true;
        pdf = transmit ? 1.0 - f : f;
        weight = transmit ? b.tint / (b.eta * b.eta) : b.tint;
    } else {
        wi_world = to_world(b, wi);
        if ((dot(wi_world, s.ng) > 0.0) == transmit) return BSDF_SAMPLE_FAILED;
        vec3 value = rough_dielectric_eval(b, wo, wi, pdf);
        if (pdf <= 0.0) return BSDF_SAMPLE_FAILED;
        weight = value / pdf;
        return BSDF_SAMPLE_DONE;
    }
    return BSDF_SAMPLE_CONTINUE;
}

// Beer-Lambert absorption coefficient (per metre) inside a dielectric; zero elsewhere.
vec3 material_absorption(int m) {
    return HAS_MATERIAL(MATERIAL_DIELECTRIC) && material_type(m) == MATERIAL_DIELECTRIC ? material_row(m, 5).xyz : vec3(0.0);
}
