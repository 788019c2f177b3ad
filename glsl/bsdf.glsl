// Scattering at a surface. Every material provides three things that agree with one another:
// evaluation (f |cos theta_i|), its pdf, and importance sampling that returns f |cos| / pdf.
// Directions are world-space unit vectors; wo points back along the arriving ray. Work happens in the
// local shading frame (normal = +Z), which surface_at() has already turned towards wo: reflecting
// materials are two-sided without the user having to say so, and dielectrics know from front_face
// whether the ray is entering or leaving.
//
// A material is MATERIAL_ROWS vec4 rows (scene/materials/, packed through render/buffers.py's pack_material);
// its type, one of the MATERIAL_* codes, is in row 0, w. Both come from render/gpu_layout.py as #defines.
// Each kind's own code is in its include, glsl/material_<kind>.glsl; "material_kinds.glsl" is generated from
// the registry (scene/materials/registry.py's glsl_dispatch): it includes them all and defines material_eval
// and material_sample, which bsdf_eval_untilted and bsdf_sample_untilted below call for the Bsdf's kind.

vec4 material_row(int m, int row) { return materials[MATERIAL_ROWS * m + row]; }
int material_type(int m) { return int(material_row(m, 0).w); }
// The first material m holds (an Emissive's surface, a wrapper's material, a blend's first), or -1.
int inner_material(int m) { return int(material_row(m, 2).x); }
// Whether a hit on m scatters light: everything but a light without a surface.
bool material_scatters(int m) { return material_type(m) != MATERIAL_EMISSIVE || inner_material(m) >= 0; }

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

// -- Materials that hold materials (scene/materials/) ----------------------------------------------------
// A hit on one walks down to the material that scatters: a light's surface, one of a blend's two (picked
// with the blend's odds, which keeps the estimate unbiased, as pbrt-v4's MixMaterial), the material under a
// mask (whose cut-out traversal already applied: mask.glsl) or under a bump or normal map, which tilt the
// shading normal on the way. Compiled only for scenes that have such materials (HAS_NESTED_MATERIALS).

// A texture's scalar value, as Mitsuba's eval_1 reads a colour texture: its luminance.
float texture_value(int t, vec2 uv) { return luminance(texture_rgb(t, uv)); }

// A tilted normal the viewer sees from behind (along wo, below its tangent plane) would shade nothing:
// mirror its tilt across the untilted normal n instead, as Mitsuba's flip_invalid_normals (on by default).
vec3 facing_viewer(vec3 tilted, vec3 n, vec3 wo) {
    return dot(wo, tilted) > 0.0 ? tilted : 2.0 * dot(tilted, n) * n - tilted;
}

// b is of material type `code`: false at compile time for types the scene lacks (features.glsl).
bool is_type(Bsdf b, int code) { return HAS_MATERIAL(code) && b.type == code; }

vec3 to_local(Bsdf b, vec3 w) { return w * b.frame; }  // = transpose(frame) * w
vec3 to_world(Bsdf b, vec3 w) { return b.frame * w; }

// What a kind's sample function (material_sample) did: failed (bsdf_sample_untilted returns false), finished
// (wi_world, weight and pdf are final: returns true), or chose wi, transmit and pdf, for the checks every kind
// shares.
const int BSDF_SAMPLE_FAILED = 0;
const int BSDF_SAMPLE_DONE = 1;
const int BSDF_SAMPLE_CONTINUE = 2;

vec3 bsdf_eval_untilted(SurfaceHit s, Bsdf b, vec3 wi_world, out float pdf);  // plastic's sampling weighs by it

#include "material_kinds.glsl"

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

// f(wo, wi) |cos theta_i| and the density with which bsdf_sample would choose wi (solid angle).
// b is bsdf_at(s), resolved once per hit and shared by evaluation and sampling.
vec3 bsdf_eval_untilted(SurfaceHit s, Bsdf b, vec3 wi_world, out float pdf) {
    pdf = 0.0;
    if (bsdf_is_delta(b)) return vec3(0.0);
    vec3 wo = to_local(b, s.wo), wi = to_local(b, wi_world);
    if (wo.z <= 0.0) return vec3(0.0);
    bool same_side = dot(wi_world, s.ng) > 0.0;  // the geometric normal decides, so shading normals never leak
    return material_eval(b, wo, wi, same_side, pdf);
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
    int sampled = material_sample(s, b, u, wo, wi, transmit, wi_world, weight, pdf, delta);
    if (sampled != BSDF_SAMPLE_CONTINUE) return sampled == BSDF_SAMPLE_DONE;
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
