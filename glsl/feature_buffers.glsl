// The denoiser's guides (render/denoise.py): for each sample, the albedo and the shading normal of the surface
// the camera ray shows, taken through the same camera sample as the beauty (same pixel position, same point on
// the lens), so that the guides blur with depth of field exactly as the noisy image does. Compiled in only
// with HAS_FEATURE_BUFFERS (render/tracer.py's feature_buffers): a render without them pays nothing.
//
// Open Image Denoise's conventions for its auxiliary images (its documentation, the "RT" filter):
// * Albedo, in [0, 1]: the surface's colour whatever the light and view. A matte surface's reflectance; a
//   metal's reflectivity at normal incidence; glass its tint (OIDN: 1); a layered surface (our plastic) its
//   base, the clear coat ignored.
// * Perfect specular (delta) surfaces (smooth glass, thin glass, smooth metal) are followed to the first
//   diffuse or glossy hit, whose features are kept, its albedo times the delta lobes' weights on the way. The
//   path picks reflection or transmission with the Fresnel odds, so the average over samples is the Fresnel
//   blend of the reflected and transmitted albedos that OIDN recommends.
// * Normal: the world-space shading normal (bump and normal maps applied), turned towards the viewer. The
//   average over a pixel's samples is not unit length, as OIDN allows; it stays within [-1, 1].
// * The environment (no surface): normal 0, OIDN's and Cycles' "no surface here"; albedo the environment's
//   radiance clamped to [0, 1], as Cycles writes the background into its denoising albedo, so a visible
//   environment map keeps its detail.
// * A light without a surface: its radiance clamped to [0, 1] as albedo (as Cycles), and its normal.
// * A path that ends on a delta surface (max_depth, Russian roulette, a sample refused) keeps that surface's
//   normal and an albedo of 1 times the weights so far.
#if HAS_FEATURE_BUFFERS

vec3 feature_albedo;  // this sample's guides, written by path_radiance (integrator.glsl)
vec3 feature_normal;
vec3 feature_weight;  // product of the delta lobes' weights followed so far
bool features_open;   // still looking for the surface whose guides to keep

void features_begin() {
    feature_albedo = vec3(0.0);
    feature_normal = vec3(0.0);
    feature_weight = vec3(1.0);
    features_open = true;
}

// A material's albedo for the denoiser (see above), from its parameters at this point.
vec3 bsdf_albedo(Bsdf b) {
    if (is_type(b, MATERIAL_CONDUCTOR)) return b.tint * fresnel_conductor(1.0, b.eta3, b.k);
    if (is_type(b, MATERIAL_DIELECTRIC) || is_type(b, MATERIAL_THIN_DIELECTRIC)) return b.tint;
    return b.color;  // diffuse, and plastic's base under its coat
}

void features_at_miss(vec3 environment) {
    if (!features_open) return;
    feature_albedo = clamp(feature_weight * environment, 0.0, 1.0);
    feature_normal = vec3(0.0);
    features_open = false;
}

void features_at_light(SurfaceHit s, vec3 emitted) {
    if (!features_open) return;
    feature_albedo = clamp(feature_weight * emitted, 0.0, 1.0);
    feature_normal = s.ns;
    features_open = false;
}

// A surface that scatters: keep its guides, unless it is a delta surface the path may go on through
// (go_on false: the path ends here), whose guides are kept only until the path reaches something else.
void features_at_surface(Bsdf b, bool go_on) {
    if (!features_open) return;
    feature_normal = b.frame[2];
    bool delta = bsdf_is_delta(b);
    feature_albedo = clamp(feature_weight * (delta ? vec3(1.0) : bsdf_albedo(b)), 0.0, 1.0);
    features_open = delta && go_on;
}

// The path went on through a delta lobe whose sample weight (f |cos| / pdf, radiance compression undone) this is.
void features_follow(vec3 weight) {
    if (features_open) feature_weight *= weight;
}

#endif
