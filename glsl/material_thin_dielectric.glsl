// ThinDielectric (scene/materials/thin_dielectric.py): a pane that reflects, and lets light through unbent.
// Only Dirac lobes, so nothing to evaluate (bsdf_is_delta). Included by glsl/bsdf.glsl through the generated
// dispatch (scene/materials/registry.py).

int thin_dielectric_sample(SurfaceHit s, Bsdf b, vec3 u, vec3 wo, inout vec3 wi, inout bool transmit,
                           inout vec3 wi_world, inout vec3 weight, inout float pdf, inout bool delta) {
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
    return BSDF_SAMPLE_CONTINUE;
}
