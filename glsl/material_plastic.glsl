// Plastic (scene/materials/plastic.py): a diffuse base under a smooth or rough dielectric coating.
// Included by glsl/bsdf.glsl through the generated dispatch (scene/materials/registry.py).

// Share of light the coating lets through at this angle: 1 - Fresnel when smooth, the rough interface's
// tabulated directional transmittance otherwise (render/fresnel.rough_transmittance_table, as Mitsuba's
// roughplastic: the microfacets shadow part of what refracts, so it is less than 1 - reflectance).
float plastic_transmittance(Bsdf b, float cos_theta) {
    if (b.alpha == 0.0) return 1.0 - fresnel_dielectric(cos_theta, b.eta);
    float x = clamp(cos_theta, 0.0, 1.0) * float(ROUGH_TABLE_SIZE - 1);
    int i = min(int(x), ROUGH_TABLE_SIZE - 2);
    uint at = uint(b.transmittance_table + i);
    return mix(uintBitsToFloat(image_data[at]), uintBitsToFloat(image_data[at + 1u]), x - float(i));
}

// The probability of choosing the coating's reflection when sampling (Mitsuba's heuristic).
float plastic_specular_probability(Bsdf b, float cos_o) {
    float f = 1.0 - plastic_transmittance(b, cos_o);
    float d = (b.color.x + b.color.y + b.color.z) / 3.0;
    float spec_weight = 1.0 / (1.0 + d);
    float p_spec = f * spec_weight;
    float p_diff = (1.0 - f) * (1.0 - spec_weight);
    return p_spec / max(p_spec + p_diff, 1e-12);
}

vec3 plastic_diffuse(Bsdf b, float cos_o, float cos_i) {
    float t = plastic_transmittance(b, cos_i) * plastic_transmittance(b, cos_o);
    return b.color / (1.0 - b.internal_reflectance) * (t / (b.eta * b.eta)) * INV_PI * cos_i;
}

vec3 plastic_eval(Bsdf b, vec3 wo, vec3 wi, bool same_side, inout float pdf) {
    if (!same_side || wi.z <= 0.0) return vec3(0.0);
    vec3 m = normalize(wo + wi);
    float p_spec = plastic_specular_probability(b, wo.z);
    vec3 value = plastic_diffuse(b, wo.z, wi.z);
    pdf = (1.0 - p_spec) * wi.z * INV_PI;
    if (b.alpha > 0.0) {
        float f = fresnel_dielectric(dot(wo, m), b.eta);
        value += vec3(f * microfacet_d(m, b.alpha, b.beckmann) * microfacet_g(wo, wi, b.alpha, b.beckmann) / (4.0 * wo.z));
        pdf += p_spec * microfacet_pdf(wo, m, b.alpha, b.beckmann) / (4.0 * dot(wo, m));
    }
    return value;
}

int plastic_sample(SurfaceHit s, Bsdf b, vec3 u, vec3 wo, inout vec3 wi, inout bool transmit, inout vec3 wi_world,
                   inout vec3 weight, inout float pdf, inout bool delta) {
    float p_spec = plastic_specular_probability(b, wo.z);
    if (u.z < p_spec) {
        vec3 m = b.alpha == 0.0 ? vec3(0.0, 0.0, 1.0) : microfacet_sample(wo, b.alpha, b.beckmann, u.xy);
        wi = 2.0 * dot(wo, m) * m - wo;
        if (wi.z <= 0.0) return BSDF_SAMPLE_FAILED;
        if (b.alpha == 0.0) {
            delta = true;
            pdf = p_spec;
            weight = vec3(fresnel_dielectric(wo.z, b.eta) / p_spec);
        }
    } else {
        wi = sample_cosine_hemisphere(u.xy);
    }
    if (!delta) {  // both lobes can produce this direction: weigh by the full density
        wi_world = to_world(b, wi);
        if (dot(wi_world, s.ng) <= 0.0) return BSDF_SAMPLE_FAILED;
        vec3 f = bsdf_eval_untilted(s, b, wi_world, pdf);
        if (pdf <= 0.0) return BSDF_SAMPLE_FAILED;
        weight = f / pdf;
        return BSDF_SAMPLE_DONE;
    }
    return BSDF_SAMPLE_CONTINUE;
}
