// Cut-outs (scene/materials.py's Mask): a ray passes a masked surface with probability 1 - opacity, as if
// the surface were not there. The choice is made during traversal (bsp.glsl), so camera rays, bounces and
// shadow rays all see the same partial surface and next-event estimation stays unbiased. It is a hash of the
// ray and the primitive (as pbrt-v4's alpha test), not a number from the sampler: the same ray asks the same
// question of a primitive in every kd-tree leaf that holds it.
//
// Included (before bsp.glsl) by the trace kernel only: picking and focusing (raycast.comp) see masked
// surfaces as solid, which is what a click on a leaf means.

#define MASKED_TRAVERSAL 1

// The product of the opacities of the masks on the way down from material m to the material that scatters
// (through bump and normal maps and a light's surface; a blend's pick is not known here, so a mask inside a
// blend does not cut: the importer says so).
float material_opacity(int m, vec2 uv) {
    float opacity = 1.0;
    for (int level = 0; level < MATERIAL_NESTING && m >= 0; level++) {
        vec4 r0 = materials[MATERIAL_ROWS * m];
        int type = int(r0.w);
        if (type == MATERIAL_MASK) {
            opacity *= clamp(r0.y >= 0.0 ? luminance(texture_rgb(int(r0.y), uv)) : r0.x, 0.0, 1.0);
        } else if (type != MATERIAL_BUMP_MAP && type != MATERIAL_NORMAL_MAP && type != MATERIAL_EMISSIVE) {
            break;
        }
        m = int(materials[MATERIAL_ROWS * m + 2].x);
    }
    return opacity;
}

// Whether the ray passes through prim at parameter t (barycentrics bary) rather than hitting it.
bool passes_through(Ray ray, int prim, float t, vec2 bary) {
    int m = material_of(prim);
    int type = int(materials[MATERIAL_ROWS * m].w);
    if (type != MATERIAL_MASK && type != MATERIAL_BUMP_MAP && type != MATERIAL_NORMAL_MAP && type != MATERIAL_EMISSIVE)
        return false;
    vec2 uv;
    if (is_sphere(prim)) {
        vec4 sphere = geometry[GEOMETRY_ROWS * prim];
        uv = sphere_uv(normalize(ray.o + t * ray.d - sphere.xyz));
    } else {
        uv = triangle_uv(prim, bary);
    }
    float opacity = material_opacity(m, uv);
    if (opacity >= 1.0) return false;
    return hash_unit(ray.o, ray.d.xy, floatBitsToUint(ray.d.z) ^ hash_u32(uint(prim))) >= opacity;
}
