// Unidirectional path tracing with next-event estimation and multiple importance sampling (Veach 1997,
// power heuristic), as in pbrt-v4's PathIntegrator. Path length follows Mitsuba's max_depth: 1 sees only
// emitters, 2 adds direct light, and so on. Russian roulette from rr_depth keeps the estimator unbiased.

uniform int max_depth;
uniform int rr_depth;

vec3 path_radiance(Ray ray, inout Sampler sampler) {
    vec3 radiance = vec3(0.0);
    vec3 throughput = vec3(1.0);
    float prev_bsdf_pdf = 0.0;
    bool prev_delta = true;  // the camera ray: nothing to weigh emission against
    vec3 prev_p = ray.o;
    float prev_light_weights = 1.0;  // LightChoice.weights at prev_p: MIS needs the light choice made there
    float eta_scale = 1.0;  // radiance compression by refraction so far (see bsdf_eta_scale)
#if HAS_FEATURE_BUFFERS
    features_begin();  // the denoiser's guides (feature_buffers.glsl): they read the path, never change it
#endif

    for (int segments = 1; ; segments++) {
        Hit hit;
        if (!trace_scene(ray, 0.0, INFINITY, false, hit)) {
            // The ray leaves the scene: the sky, and the sun's disk if it looks straight at it.
            vec3 le = environment_radiance(ray.d);
#if HAS_FEATURE_BUFFERS
            features_at_miss(le);
#endif
            float w = prev_delta ? 1.0 : power_heuristic(prev_bsdf_pdf, environment_pdf(ray.d,
                                                          light_choice_pmf(env_light, prev_p, prev_light_weights)));
            radiance += throughput * le * w;
            vec3 sun = sun_seen(ray.d);
            if (max_component(sun) > 0.0) {
                float pmf = light_choice_pmf(sun_light, prev_p, prev_light_weights);
                radiance += throughput * sun * (prev_delta ? 1.0 : power_heuristic(prev_bsdf_pdf, sun_pdf(pmf)));
            }
            break;
        }
        SurfaceHit s = surface_at(ray, hit);
        if (!s.front_face) {
            // The ray travelled inside this object: Beer-Lambert absorption over the distance (zero unless glass).
            throughput *= exp(-material_absorption(s.material) * hit.t);
        }

        vec3 le = emitted_radiance(s.material, s.front_face);
        if (max_component(le) > 0.0) {
            float w = 1.0;
            if (!prev_delta) {
                // ng was turned towards the ray; the light pdf only needs |cos|, so its sign does not matter.
                float pmf = light_choice_pmf(light_of(s.prim), prev_p, prev_light_weights);
                w = power_heuristic(prev_bsdf_pdf, area_light_pdf(s.prim, prev_p, s.p, s.ng, pmf));
            }
            radiance += throughput * le * w;
        }
        if (segments >= max_depth || !material_scatters(s.material)) {
#if HAS_FEATURE_BUFFERS
            if (features_open && material_scatters(s.material)) features_at_surface(bsdf_at(s), false);
            else features_at_light(s, le);
#endif
            break;
        }

        Bsdf bsdf = bsdf_at(s);
#if HAS_FEATURE_BUFFERS
        features_at_surface(bsdf, true);
#endif
        vec4 u_light = sample4(sampler);
        vec4 u_bsdf = sample4(sampler);

        // Next-event estimation: one shadow ray towards a light chosen for this point (lights.glsl).
        LightChoice choice = choose_light(s.p, u_light.x);
        LightSample ls;
        if (sample_light(s.p, choice, u_light.yz, ls)) {
            float bsdf_pdf;
            vec3 f = bsdf_eval(s, bsdf, ls.wi, bsdf_pdf);
            if (max_component(f) > 0.0) {
                Ray shadow = spawn_ray(s, ls.wi);
                float t_max = INFINITY;
                if (!isinf(ls.dist)) {
                    // Aim from the nudged origin at the light's point itself, and stop just short of it by
                    // the same kind of margin: a surface facing the light head-on is nudged towards it,
                    // and a margin measured from the un-nudged point would let the ray hit the light.
                    vec3 q = s.p + ls.wi * ls.dist;
                    vec3 to_q = q - shadow.o;
                    float len = length(to_q);
                    shadow.d = to_q / len;
                    t_max = len - 1e-4 * (1.0 + max_component(abs(q)));
                }
                if (t_max > 0.0 && !occluded(shadow, t_max)) {
                    float w = ls.delta ? 1.0 : power_heuristic(ls.pdf, bsdf_pdf);
                    radiance += throughput * f * ls.radiance * (w / ls.pdf);
                }
            }
        }

        // Continue the path by sampling the BSDF.
        vec3 wi, weight;
        float pdf;
        bool delta;
        if (!bsdf_sample(s, bsdf, u_bsdf.xyz, wi, weight, pdf, delta)) break;
        throughput *= weight;
        eta_scale *= bsdf_eta_scale(s, bsdf, wi);
#if HAS_FEATURE_BUFFERS
        features_follow(weight * bsdf_eta_scale(s, bsdf, wi));  // glass's tint, not its 1/eta^2
#endif
        prev_bsdf_pdf = pdf;
        prev_delta = delta;
        prev_p = s.p;
        prev_light_weights = choice.weights;
        ray = spawn_ray(s, wi);

        if (segments >= rr_depth) {
            // Survive with probability q (at most 0.95), then divide by it: unbiased.
            float q = min(max_component(throughput) * eta_scale, 0.95);
            if (u_bsdf.w >= q) break;
            throughput /= q;
        }
    }
    return radiance;
}
