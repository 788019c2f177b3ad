// Fresnel equations and the GGX (Trowbridge-Reitz) and Beckmann microfacet distributions, in the local
// shading frame where the normal is +Z. Conventions follow pbrt-v4 (section 9.6): alpha is the distribution's
// width, eta the ratio of the indices of refraction n_transmitted / n_incident. The microfacet_* functions at
// the end serve either distribution; bsdf.glsl calls only those.

// Unpolarised Fresnel reflectance of a dielectric boundary for light arriving at cos_i > 0.
// Returns 1 on total internal reflection.
float fresnel_dielectric(float cos_i, float eta) {
    cos_i = clamp(cos_i, 0.0, 1.0);
    float sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) return 1.0;
    float cos_t = sqrt(1.0 - sin2_t);
    float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_parl * r_parl + r_perp * r_perp);
}

// Fresnel reflectance of a conductor with complex index eta + i k (per channel), pbrt-v4's FrComplex.
vec3 fresnel_conductor(float cos_i, vec3 eta, vec3 k) {
    cos_i = clamp(cos_i, 0.0, 1.0);
    float cos2 = cos_i * cos_i;
    float sin2 = 1.0 - cos2;
    vec3 eta2 = eta * eta, k2 = k * k;
    vec3 t0 = eta2 - k2 - sin2;
    vec3 a2b2 = sqrt(max(t0 * t0 + 4.0 * eta2 * k2, 0.0));
    vec3 a = sqrt(max(0.5 * (a2b2 + t0), 0.0));
    vec3 t1 = a2b2 + cos2;
    vec3 t2 = 2.0 * cos_i * a;
    vec3 rs = (t1 - t2) / max(t1 + t2, 1e-12);
    vec3 t3 = cos2 * a2b2 + sin2 * sin2;
    vec3 t4 = t2 * sin2;
    vec3 rp = rs * (t3 - t4) / max(t3 + t4, 1e-12);
    return 0.5 * (rp + rs);
}

// Refract w (pointing away from the surface, on the side of n) through a boundary with relative index eta.
// Returns false on total internal reflection.
bool refract_dir(vec3 w, vec3 n, float eta, out vec3 wt) {
    float cos_i = dot(n, w);
    float sin2_t = max(0.0, 1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) return false;
    float cos_t = sqrt(1.0 - sin2_t);
    wt = -w / eta + (cos_i / eta - cos_t) * n;
    return true;
}

float ggx_d(vec3 m, float alpha) {
    float cos2 = m.z * m.z;
    if (cos2 <= 0.0) return 0.0;
    float a2 = alpha * alpha;
    float denom = cos2 * (a2 - 1.0) + 1.0;
    return a2 / (PI * denom * denom);
}

float ggx_lambda(vec3 w, float alpha) {
    float cos2 = w.z * w.z;
    if (cos2 <= 0.0) return 0.0;
    float tan2 = max(0.0, 1.0 - cos2) / cos2;
    return 0.5 * (sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}

float ggx_g1(vec3 w, float alpha) { return 1.0 / (1.0 + ggx_lambda(w, alpha)); }
float ggx_g(vec3 wo, vec3 wi, float alpha) { return 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha)); }

// Visible normals of wo (wo.z > 0): Heitz 2018 "Sampling the GGX Distribution of Visible Normals".
vec3 ggx_sample_visible_normal(vec3 wo, float alpha, vec2 u) {
    vec3 wh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
    float len2 = wh.x * wh.x + wh.y * wh.y;
    vec3 t1 = len2 > 0.0 ? vec3(-wh.y, wh.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(wh, t1);
    vec2 p = sample_concentric_disk(u);
    float h = sqrt(max(0.0, 1.0 - p.x * p.x));
    float s = 0.5 * (1.0 + wh.z);
    p.y = (1.0 - s) * h + s * p.y;
    float pz = sqrt(max(0.0, 1.0 - dot(p, p)));
    vec3 nh = p.x * t1 + p.y * t2 + pz * wh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-6, nh.z)));
}

// Density of the visible normal m seen from wo: G1(wo) max(0, wo.m) D(m) / cos(wo).
float ggx_visible_normal_pdf(vec3 wo, vec3 m, float alpha) {
    return ggx_g1(wo, alpha) * max(0.0, dot(wo, m)) * ggx_d(m, alpha) / wo.z;
}

// -- Beckmann ---------------------------------------------------------------------------------------------
// D(m) = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4), Smith's Lambda by Walter et al.'s rational fit (2007),
// which is also Mitsuba's, so that a Beckmann surface imported from Mitsuba scatters as it does there.
float beckmann_d(vec3 m, float alpha) {
    float cos2 = m.z * m.z;
    if (cos2 <= 0.0) return 0.0;
    float a2 = alpha * alpha;
    float tan2 = max(0.0, 1.0 - cos2) / cos2;
    return exp(-tan2 / a2) / (PI * a2 * cos2 * cos2);
}

float beckmann_lambda(vec3 w, float alpha) {
    float cos2 = w.z * w.z;
    if (cos2 <= 0.0) return 0.0;
    float tan_theta = sqrt(max(0.0, 1.0 - cos2) / cos2);
    float a = 1.0 / max(alpha * tan_theta, 1e-20);
    if (a >= 1.6) return 0.0;
    return (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}

// Normals drawn with density D(m) cos(theta_m) (tan^2 theta = -alpha^2 ln(1 - u)): simpler than Beckmann's
// visible normals and just as unbiased, at a little more noise near grazing angles.
vec3 beckmann_sample_normal(float alpha, vec2 u) {
    float tan2 = -alpha * alpha * log(1.0 - min(u.x, ONE_MINUS_EPSILON));
    float cos_theta = inversesqrt(1.0 + tan2);
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * PI * u.y;
    return vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// -- Either distribution ----------------------------------------------------------------------------------
float microfacet_d(vec3 m, float alpha, bool beckmann) {
    return beckmann ? beckmann_d(m, alpha) : ggx_d(m, alpha);
}

float microfacet_lambda(vec3 w, float alpha, bool beckmann) {
    return beckmann ? beckmann_lambda(w, alpha) : ggx_lambda(w, alpha);
}

float microfacet_g1(vec3 w, float alpha, bool beckmann) { return 1.0 / (1.0 + microfacet_lambda(w, alpha, beckmann)); }

// Height-correlated masking-shadowing.
float microfacet_g(vec3 wo, vec3 wi, float alpha, bool beckmann) {
    return 1.0 / (1.0 + microfacet_lambda(wo, alpha, beckmann) + microfacet_lambda(wi, alpha, beckmann));
}

// A microfacet normal for light leaving along wo (wo.z > 0): GGX's visible normals, Beckmann's D cos.
vec3 microfacet_sample(vec3 wo, float alpha, bool beckmann, vec2 u) {
    return beckmann ? beckmann_sample_normal(alpha, u) : ggx_sample_visible_normal(wo, alpha, u);
}

// The density with which microfacet_sample draws m.
float microfacet_pdf(vec3 wo, vec3 m, float alpha, bool beckmann) {
    if (beckmann) return beckmann_d(m, alpha) * max(m.z, 0.0);
    return ggx_visible_normal_pdf(wo, m, alpha);
}

// f |cos theta_i| / pdf of a reflection about m drawn by microfacet_sample, Fresnel left out: G / G1(wo) for
// visible normals; G (wo.m) / (wo.z m.z) for normals drawn from D cos.
float microfacet_reflection_weight(vec3 wo, vec3 wi, vec3 m, float alpha, bool beckmann) {
    if (beckmann) return microfacet_g(wo, wi, alpha, true) * dot(wo, m) / (wo.z * m.z);
    return microfacet_g(wo, wi, alpha, false) / ggx_g1(wo, alpha);
}
