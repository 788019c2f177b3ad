// Scattering at a surface. Every material provides three functions that agree with one another:
// evaluation (f * |cos theta_i|), its pdf, and importance sampling that returns f * |cos| / pdf.
// Directions are world-space unit vectors; wo points away from the surface, towards where light goes.

const int MATERIAL_DIFFUSE = 0;
const int MATERIAL_EMISSIVE = 1;

int material_type(int m) { return int(materials[4 * m].w); }
vec3 material_albedo(int m) { return materials[4 * m].xyz; }

bool material_scatters(int m) { return material_type(m) != MATERIAL_EMISSIVE; }

// Radiance a surface emits towards wo.
vec3 emitted_radiance(int m, bool front_face) {
    vec4 e = materials[4 * m + 1];
    return (front_face || e.w > 0.5) ? e.xyz : vec3(0.0);
}

// f(wo, wi) |cos theta_i|, with pdf the density bsdf_sample would have chosen wi with (solid angle).
vec3 bsdf_eval(SurfaceHit s, vec3 wi, out float pdf) {
    pdf = 0.0;
    float cos_i = dot(wi, s.ns);
    // Light must arrive on the side the ray came from: a shading normal must not let it leak through.
    if (material_type(s.material) != MATERIAL_DIFFUSE || cos_i <= 0.0 || dot(wi, s.ng) <= 0.0) return vec3(0.0);
    pdf = cos_i * INV_PI;
    return material_albedo(s.material) * INV_PI * cos_i;
}

// Sample wi; weight = f |cos| / pdf. delta = the lobe is a Dirac (no MIS with light sampling possible).
bool bsdf_sample(SurfaceHit s, vec3 u, out vec3 wi, out vec3 weight, out float pdf, out bool delta) {
    delta = false;
    weight = vec3(0.0);
    pdf = 0.0;
    if (material_type(s.material) != MATERIAL_DIFFUSE) return false;
    wi = frame_around(s.ns) * sample_cosine_hemisphere(u.xy);
    if (dot(wi, s.ng) <= 0.0) return false;
    pdf = dot(wi, s.ns) * INV_PI;
    if (pdf <= 0.0) return false;
    weight = material_albedo(s.material);  // (albedo / pi) cos / (cos / pi)
    return true;
}
