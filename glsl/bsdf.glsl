// Scattering at a surface. Every material provides three things that agree with one another:
// evaluation (f |cos theta_i|), its pdf, and importance sampling that returns f |cos| / pdf.
// Directions are world-space unit vectors; wo points back along the arriving ray. Work happens in the
// local shading frame (normal = +Z), which surface_at() has already turned towards wo: reflecting
// materials are two-sided without the user having to say so, and dielectrics know from front_face
// whether the ray is entering or leaving.
//
// A material is MATERIAL_ROWS vec4 rows (render/buffers.py's pack_material); its type, one of the MATERIAL_*
// codes, is in row 0, w. Both come from render/gpu_layout.py as #defines.

vec4 material_row(int m, int row) { return materials[MATERIAL_ROWS * m + row]; }
int material_type(int m) { return int(material_row(m, 0).w); }
// The first material m holds (an Emissive's surface, a wrapper's material, a blend's first), or -1.
int inner_material(int m) { return int(material_row(m, 2).x); }
// Whether a hit on m scatters light: everything but a light without a surface.
bool material_scatters(int m) { return material_type(m) != MATERIAL_EMISSIVE || inner_material(m) >= 0; }

// Radiance a surface emits towards wo.
vec3 emitted_radiance(int m, bool front_face) {
    vec4 e = material_row(m, 1);
    return (front_face || e.w > 0.5) ? e.xyz : vec3(0.0);
}

// Beer-Lambert absorption coefficient (per metre) inside a dielectric; zero elsewhere.
vec3 material_absorption(int m) {
    return HAS_MATERIAL(MATERIAL_DIELECTRIC) && material_type(m) == MATERIAL_DIELECTRIC ? material_row(m, 5).xyz : vec3(0.0);
}

// A material's parameters at one surface point, textures resolved.
struct Bsdf {
    int type;
    vec3 color;   // diffuse albedo
    vec3 tint;    // specular tint
    float alpha;  // microfacet width; 0 = smooth
    bool beckmann; // the microfacet distribution: Beckmann, or GGX
    float eta;    // dielectrics: n_inside / n_outside, inverted when leaving; plastic: coating index
    vec3 eta3;    // conductors: complex index
    vec3 k;
    float internal_reflectance;  // plastic: diffuse Fresnel reflectance inside the coating
    int transmittance_table;     // rough plastic: the coating's transmittance, ROUGH_TABLE_SIZE entries in image_data
    mat3 frame;   // local shading frame: columns tangent, bitangent, normal
    vec3 base_normal;  // the shading normal before bump and normal maps tilted it (frame's z after)
    float terminator;  // their shadowing term's alpha^2 (shadow_terminator); 0: none
};

// -- Materials that hold materials (scene/materials.py) --------------------------------------------------
// A hit on one walks down to the material that scatters: a light's surface, one of a blend's two (picked
// with the blend's odds, which keeps the estimate unbiased, as pbrt-v4's MixMaterial), the material under a
// mask (whose cut-out traversal already applied: mask.glsl) or under a bump or normal map, which tilt the
// shading normal on the way. Compiled only for scenes that have such materials (HAS_NESTED_MATERIALS).

// A number in [0, 1) from the hit itself, so that choosing within a blend takes no dimension of the sampler.
float hit_hash(SurfaceHit s, int level) {
    return hash_unit(s.p, s.wo.xy, floatBitsToUint(s.wo.z) + uint(level));
}

// A texture's scalar value, as Mitsuba's eval_1 reads a colour texture: its luminance.
float texture_value(int t, vec2 uv) { return luminance(texture_rgb(t, uv)); }

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

// A tilted normal the viewer sees from behind (along wo, below its tangent plane) would shade nothing:
// mirror its tilt across the untilted normal n instead, as Mitsuba's flip_invalid_normals (on by default).
vec3 facing_viewer(vec3 tilted, vec3 n, vec3 wo) {
    return dot(wo, tilted) > 0.0 ? tilted : 2.0 * dot(tilted, n) * n - tilted;
}

// The material that scatters at s, its shading normal (s.ns, tilted by bump and normal maps) and the alpha^2
// of their shadowing term (0: none).
int resolve_material(SurfaceHit s, out vec3 ns, out float terminator) {
    ns = s.ns;
    terminator = 0.0;
    int m = s.material;
#if HAS_NESTED_MATERIALS
    // Maps tilt the normal as the front face sees it; a hit from behind sees the mirror image (the
    // surface looks the same from both sides, as Mitsuba's twosided).
    vec3 n_front = s.front_face ? s.ns : -s.ns;
    vec3 n = n_front, ng = s.front_face ? s.ng : -s.ng;
    vec3 wo = s.front_face ? s.wo : s.wo - 2.0 * dot(s.wo, n_front) * n_front;
    bool tilted = false, shadowing = false;
    for (int level = 0; level < MATERIAL_NESTING; level++) {
        vec4 r0 = material_row(m, 0);
        int type = int(r0.w);
        int inner = inner_material(m);
        // Each kind compiled in only where the scene has it (features.glsl): the maps' code is large.
        if (HAS_MATERIAL(MATERIAL_BLEND) && type == MATERIAL_BLEND) {
            float weight = r0.y >= 0.0 ? texture_value(int(r0.y), s.uv) : r0.x;
            if (hit_hash(s, level) < weight) inner = int(material_row(m, 2).y);
        } else if ((HAS_MATERIAL(MATERIAL_BUMP_MAP) && type == MATERIAL_BUMP_MAP) ||
                   (HAS_MATERIAL(MATERIAL_NORMAL_MAP) && type == MATERIAL_NORMAL_MAP)) {
            if (r0.y >= 0.0) {
                vec3 t = (HAS_MATERIAL(MATERIAL_BUMP_MAP) && type == MATERIAL_BUMP_MAP)
                             ? bumped_normal(s, n, ng, int(r0.y), r0.x) : mapped_normal(s, n, int(r0.y));
                n = facing_viewer(t, n, wo);
                tilted = true;
                shadowing = shadowing || r0.z > 0.5;
            }
        } else if (type != MATERIAL_MASK && type != MATERIAL_EMISSIVE) {
            break;
        }
        if (inner < 0) break;  // a light without a surface
        m = inner;
    }
    if (tilted) {
        ns = s.front_face ? n : n - 2.0 * dot(n, n_front) * n_front;
        if (dot(ns, s.ng) <= 0.0) ns = s.ns;  // tilted under the surface: keep the untilted normal
        if (shadowing) {
            float c = clamp(dot(ns, s.ns), 1e-6, 1.0);
            terminator = min(0.125 * (1.0 - c * c) / (c * c), 1.0);
        }
    }
#endif
    return m;
}

// Bump and normal maps tilt the shading normal without moving the surface, so light arriving low over the
// true surface lights microfacets that the bumps would have shadowed, and shadows end in hard steps. Estevez et
// al. 2019 ("A Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem") attenuate by a Smith
// shadowing term whose roughness grows with the tilt: G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2)), the light's angle
// measured from the untilted normal. Mitsuba's bumpmap and normalmap apply it by default; so do we.
float shadow_terminator(Bsdf b, vec3 wi) {
    if (b.terminator <= 0.0) return 1.0;
    float c = dot(wi, b.base_normal);
    float c2 = max(c * c, 1e-12);
    return 2.0 / (1.0 + sqrt(1.0 + b.terminator * max(0.0, 1.0 - c2) / c2));
}

// b is of material type `code`: false at compile time for types the scene lacks (features.glsl).
bool is_type(Bsdf b, int code) { return HAS_MATERIAL(code) && b.type == code; }

Bsdf bsdf_at(SurfaceHit s) {
    Bsdf b;
    vec3 ns;
    int m = resolve_material(s, ns, b.terminator);
    b.base_normal = s.ns;
    vec4 r0 = material_row(m, 0), r2 = material_row(m, 2), r3 = material_row(m, 3), r4 = material_row(m, 4);
    b.type = int(r0.w);
    b.color = r0.xyz;
    b.eta3 = r2.xyz;
    b.alpha = r2.w;
    b.k = r3.xyz;
    b.tint = r4.xyz;
    b.eta = r2.x;
    b.internal_reflectance = r2.y;
    b.transmittance_table = floatBitsToInt(r2.z);
    b.beckmann = HAS_BECKMANN != 0 && int(material_row(m, 5).w) == MICROFACET_BECKMANN;
    if (HAS_TEXTURES != 0 && r3.w >= 0.0) b.color = texture_rgb(int(r3.w), s.uv);
    if (HAS_TEXTURES != 0 && r4.w >= 0.0) {  // roughness texture: perceptual roughness in the red channel
        float r = texture_rgb(int(r4.w), s.uv).x;
        b.alpha = r * r;
    }
    if (is_type(b, MATERIAL_DIELECTRIC) && !s.front_face) b.eta = 1.0 / b.eta;
    b.alpha = b.alpha > 0.0 ? max(b.alpha, 1e-4) : 0.0;  // keep tiny roughness out of float trouble
    b.frame = frame_around(ns);
    return b;
}

bool bsdf_is_delta(Bsdf b) {
    return is_type(b, MATERIAL_THIN_DIELECTRIC) ||
           ((is_type(b, MATERIAL_CONDUCTOR) || is_type(b, MATERIAL_DIELECTRIC)) && b.alpha == 0.0);
}

vec3 to_local(Bsdf b, vec3 w) { return w * b.frame; }  // = transpose(frame) * w
vec3 to_world(Bsdf b, vec3 w) { return b.frame * w; }

// -- plastic ------------------------------------------------------------------------------------------
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

// f(wo, wi) |cos theta_i| and the density with which bsdf_sample would choose wi (solid angle).
// b is bsdf_at(s), resolved once per hit and shared by evaluation and sampling.
vec3 bsdf_eval_untilted(SurfaceHit s, Bsdf b, vec3 wi_world, out float pdf) {
    pdf = 0.0;
    if (bsdf_is_delta(b)) return vec3(0.0);
    vec3 wo = to_local(b, s.wo), wi = to_local(b, wi_world);
    if (wo.z <= 0.0) return vec3(0.0);
    bool same_side = dot(wi_world, s.ng) > 0.0;  // the geometric normal decides, so shading normals never leak
    if (is_type(b, MATERIAL_DIELECTRIC)) {
        if (same_side != (wi.z > 0.0)) return vec3(0.0);
        return rough_dielectric_eval(b, wo, wi, pdf);
    }
    if (!same_side || wi.z <= 0.0) return vec3(0.0);
    if (is_type(b, MATERIAL_DIFFUSE)) {
        pdf = wi.z * INV_PI;
        return b.color * INV_PI * wi.z;
    }
    vec3 m = normalize(wo + wi);
    if (is_type(b, MATERIAL_CONDUCTOR)) {
        pdf = microfacet_pdf(wo, m, b.alpha, b.beckmann) / (4.0 * dot(wo, m));
        vec3 f = fresnel_conductor(dot(wo, m), b.eta3, b.k);
        return b.tint * f * (microfacet_d(m, b.alpha, b.beckmann) * microfacet_g(wo, wi, b.alpha, b.beckmann) / (4.0 * wo.z));
    }
    if (is_type(b, MATERIAL_PLASTIC)) {
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
    return vec3(0.0);
}

// Sample wi given three uniform numbers; weight = f |cos| / pdf. delta: a Dirac lobe was chosen
// (no MIS against light sampling is possible for it).
bool bsdf_sample_untilted(SurfaceHit s, Bsdf b, vec3 u, out vec3 wi_world, out vec3 weight, out float pdf, out bool delta) {
    weight = vec3(0.0);
    pdf = 0.0;
    delta = false;
    wi_world = vec3(0.0);
    vec3 wo = to_local(b, s.wo);
    if (wo.z <= 0.0 || b.type == MATERIAL_EMISSIVE) return false;
    vec3 wi;
    bool transmit = false;

    if (is_type(b, MATERIAL_DIFFUSE)) {
        wi = sample_cosine_hemisphere(u.xy);
        pdf = wi.z * INV_PI;
        weight = b.color;
    } else if (is_type(b, MATERIAL_CONDUCTOR)) {
        vec3 m = b.alpha == 0.0 ? vec3(0.0, 0.0, 1.0) : microfacet_sample(wo, b.alpha, b.beckmann, u.xy);
        wi = 2.0 * dot(wo, m) * m - wo;
        if (wi.z <= 0.0) return false;
        vec3 f = b.tint * fresnel_conductor(dot(wo, m), b.eta3, b.k);
        if (b.alpha == 0.0) {
            delta = true;
            pdf = 1.0;
            weight = f;
        } else {
            pdf = microfacet_pdf(wo, m, b.alpha, b.beckmann) / (4.0 * dot(wo, m));
            weight = f * microfacet_reflection_weight(wo, wi, m, b.alpha, b.beckmann);
        }
    } else if (is_type(b, MATERIAL_PLASTIC)) {
        float p_spec = plastic_specular_probability(b, wo.z);
        if (u.z < p_spec) {
            vec3 m = b.alpha == 0.0 ? vec3(0.0, 0.0, 1.0) : microfacet_sample(wo, b.alpha, b.beckmann, u.xy);
            wi = 2.0 * dot(wo, m) * m - wo;
            if (wi.z <= 0.0) return false;
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
            if (dot(wi_world, s.ng) <= 0.0) return false;
            vec3 f = bsdf_eval_untilted(s, b, wi_world, pdf);
            if (pdf <= 0.0) return false;
            weight = f / pdf;
            return true;
        }
    } else if (is_type(b, MATERIAL_THIN_DIELECTRIC)) {
        float r = fresnel_dielectric(wo.z, b.eta);
        if (r < 1.0) r += (1.0 - r) * (1.0 - r) * r / (1.0 - r * r);  // inter-reflections inside the pane
        delta = true;
        weight = b.tint;
        if (u.z < r) {
            wi = vec3(-wo.xy, wo.z);
            pdf = r;
        } else {
            wi = -wo;
            pdf = 1.0 - r;
            transmit = true;
        }
    } else if (is_type(b, MATERIAL_DIELECTRIC)) {
        vec3 m = b.alpha == 0.0 ? vec3(0.0, 0.0, 1.0) : microfacet_sample(wo, b.alpha, b.beckmann, u.xy);
        float f = fresnel_dielectric(dot(wo, m), b.eta);
        if (u.z < f) {
            wi = 2.0 * dot(wo, m) * m - wo;
            if (wi.z <= 0.0) return false;
        } else {
            if (!refract_dir(wo, m, b.eta, wi) || wi.z >= 0.0) return false;
            transmit = true;
        }
        if (b.alpha == 0.0) {
            delta = true;
            pdf = transmit ? 1.0 - f : f;
            weight = transmit ? b.tint / (b.eta * b.eta) : b.tint;
        } else {
            wi_world = to_world(b, wi);
            if ((dot(wi_world, s.ng) > 0.0) == transmit) return false;
            vec3 value = rough_dielectric_eval(b, wo, wi, pdf);
            if (pdf <= 0.0) return false;
            weight = value / pdf;
            return true;
        }
    } else {
        return false;
    }
    wi_world = to_world(b, wi);
    // The sampled side must agree with the geometric normal: reflection stays, transmission crosses.
    if ((dot(wi_world, s.ng) > 0.0) == transmit) return false;
    return pdf > 0.0;
}

// f(wo, wi) |cos theta_i| and the density with which bsdf_sample would choose wi (solid angle), with the
// shadowing term of bump and normal maps.
vec3 bsdf_eval(SurfaceHit s, Bsdf b, vec3 wi_world, out float pdf) {
    return bsdf_eval_untilted(s, b, wi_world, pdf) * shadow_terminator(b, wi_world);
}

// Sample wi given three uniform numbers: see bsdf_sample_untilted. The shadowing term of bump and normal maps
// scales the weight, not the density, as it scales the value.
bool bsdf_sample(SurfaceHit s, Bsdf b, vec3 u, out vec3 wi_world, out vec3 weight, out float pdf, out bool delta) {
    bool ok = bsdf_sample_untilted(s, b, u, wi_world, weight, pdf, delta);
    weight *= shadow_terminator(b, wi_world);
    return ok;
}

// How much a transmission from wo to wi compresses radiance (eta^2 entering glass, 1/eta^2 leaving); 1 for
// reflection. Russian roulette divides it out so that paths inside glass are not killed for looking dim.
float bsdf_eta_scale(SurfaceHit s, Bsdf b, vec3 wi) {
    if (dot(wi, s.ng) >= 0.0 || !is_type(b, MATERIAL_DIELECTRIC)) return 1.0;
    return b.eta * b.eta;  // b.eta is already inverted when leaving
}
