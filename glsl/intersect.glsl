// Ray-primitive intersection. Both return the ray parameter of the nearest hit in (t_min, t_max), or INFINITY.

// Moller-Trumbore on the stored (v0, e1, e2) form; also returns the barycentrics (b1, b2). Without early
// returns: on a SIMD device the lanes of a group rarely all leave at the same test, so each early return only
// adds mask work (17% of a triangle test on llvmpipe); one select at the end costs less.
float intersect_triangle(Ray ray, int prim, float t_min, float t_max, out vec2 bary) {
    vec3 v0 = geometry[GEOMETRY_ROWS * prim].xyz;
    vec3 e1 = geometry[GEOMETRY_ROWS * prim + 1].xyz;
    vec3 e2 = geometry[GEOMETRY_ROWS * prim + 2].xyz;
    vec3 p = cross(ray.d, e2);
    float det = dot(e1, p);
    float inv_det = 1.0 / det;
    vec3 s = ray.o - v0;
    float b1 = dot(s, p) * inv_det;
    vec3 q = cross(s, e1);
    float b2 = dot(ray.d, q) * inv_det;
    float t = dot(e2, q) * inv_det;
    bary = vec2(b1, b2);
    bool inside = det != 0.0 && b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0;
    return inside && t > t_min && t < t_max ? t : INFINITY;
}

// Analytic sphere. The discriminant is computed as r^2 - |f - (f.d)d|^2 rather than b^2 - c, which keeps
// its precision for small spheres far away (Haines et al., Ray Tracing Gems ch. 7).
float intersect_sphere(Ray ray, int prim, float t_min, float t_max) {
    vec4 sphere = geometry[GEOMETRY_ROWS * prim];
    vec3 f = ray.o - sphere.xyz;
    float a = dot(ray.d, ray.d);
    float b = -dot(f, ray.d);
    vec3 l = f + (b / a) * ray.d;
    float disc = a * (sphere.w * sphere.w - dot(l, l));
    if (disc < 0.0) return INFINITY;
    float c = dot(f, f) - sphere.w * sphere.w;
    float q = b + sign(b) * sqrt(disc);
    if (q == 0.0) return INFINITY;
    float t0 = c / q;
    float t1 = q / a;
    float t_near = min(t0, t1);
    float t_far = max(t0, t1);
    if (t_near > t_min && t_near < t_max) return t_near;
    if (t_far > t_min && t_far < t_max) return t_far;
    return INFINITY;
}

float intersect_prim(Ray ray, int prim, float t_min, float t_max, out vec2 bary) {
    bary = vec2(0.0);
    return is_sphere(prim) ? intersect_sphere(ray, prim, t_min, t_max)
                           : intersect_triangle(ray, prim, t_min, t_max, bary);
}

// Slab test against an axis-aligned box; returns (t_enter, t_exit), empty when t_enter > t_exit.
vec2 intersect_box(Ray ray, vec3 inv_dir, vec3 box_min, vec3 box_max) {
    vec3 t0 = (box_min - ray.o) * inv_dir;
    vec3 t1 = (box_max - ray.o) * inv_dir;
    vec3 t_small = min(t0, t1);
    vec3 t_big = max(t0, t1);
    return vec2(max(max(t_small.x, t_small.y), max(t_small.z, 0.0)), min(min(t_big.x, t_big.y), t_big.z));
}
