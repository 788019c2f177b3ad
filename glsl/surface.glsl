// What the integrator knows about the point a ray hit.

struct SurfaceHit {
    vec3 p;          // position
    vec3 ng;         // geometric normal, turned towards the incoming ray (two-sided surfaces)
    vec3 ns;         // shading normal, on the same side as ng
    vec3 wo;         // direction back along the incoming ray
    vec2 uv;         // texture coordinates
    int material;
    int prim;
    bool front_face; // the ray arrived on the side the primitive's normal points to
};

SurfaceHit surface_at(Ray ray, Hit hit) {
    SurfaceHit s;
    s.prim = hit.prim;
    s.material = material_of(hit.prim);
    s.wo = -ray.d;
    s.uv = vec2(0.0);
    if (is_sphere(hit.prim)) {
        vec4 sphere = geometry[GEOMETRY_ROWS * hit.prim];
        vec3 n = normalize(ray.o + hit.t * ray.d - sphere.xyz);
        s.p = sphere.xyz + sphere.w * n;  // re-project onto the surface: less error than o + t d
        s.ng = n;
        s.ns = n;
        s.uv = vec2(atan(n.z, n.x) * (0.5 * INV_PI) + 0.5, acos(clamp(n.y, -1.0, 1.0)) * INV_PI);
    } else {
        int i = GEOMETRY_ROWS * hit.prim;
        vec3 e1 = geometry[i + 1].xyz;
        vec3 e2 = geometry[i + 2].xyz;
        float b1 = hit.uv.x, b2 = hit.uv.y, b0 = 1.0 - b1 - b2;
        s.p = geometry[i].xyz + b1 * e1 + b2 * e2;
        s.ng = normalize(cross(e1, e2));
        int j = SHADING_ROWS * hit.prim;
        vec4 s0 = shading[j], s1 = shading[j + 1], s2 = shading[j + 2], s3 = shading[j + 3];
        vec3 n = b0 * s0.xyz + b1 * s1.xyz + b2 * s2.xyz;
        s.ns = dot(n, n) > 0.0 ? normalize(n) : s.ng;
        s.uv = b0 * vec2(s0.w, s1.w) + b1 * vec2(s2.w, s3.x) + b2 * s3.yz;
    }
    s.front_face = dot(s.ng, s.wo) > 0.0;
    if (!s.front_face) {
        s.ng = -s.ng;
        s.ns = -s.ns;
    }
    if (dot(s.ns, s.ng) <= 0.0) s.ns = s.ng;  // an interpolated normal pointing under the surface: fall back
    return s;
}

// Start a new ray at p, nudged off the surface to the side it leaves on, so that it does not hit the
// surface it starts from. The nudge grows with |p| because float spacing does.
vec3 offset_origin(vec3 p, vec3 ng, vec3 dir) {
    float eps = 1e-4 * (1.0 + max_component(abs(p)));
    return p + (dot(dir, ng) > 0.0 ? eps : -eps) * ng;
}

Ray spawn_ray(SurfaceHit s, vec3 dir) {
    return Ray(offset_origin(s.p, s.ng, dir), dir);
}
