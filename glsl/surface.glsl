// What the integrator knows about the point a ray hit.

#include "texcoords.glsl"

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
        s.uv = sphere_uv(n);
    } else {
        int i = GEOMETRY_ROWS * hit.prim;
        vec3 e1 = geometry[i + 1].xyz;
        vec3 e2 = geometry[i + 2].xyz;
        float b1 = hit.uv.x, b2 = hit.uv.y, b0 = 1.0 - b1 - b2;
        s.p = geometry[i].xyz + b1 * e1 + b2 * e2;
        s.ng = normalize(cross(e1, e2));
        int j = SHADING_ROWS * hit.prim;
        vec3 n = b0 * shading[j].xyz + b1 * shading[j + 1].xyz + b2 * shading[j + 2].xyz;
        s.ns = dot(n, n) > 0.0 ? normalize(n) : s.ng;
        s.uv = triangle_uv(hit.prim, hit.uv);
    }
    s.front_face = dot(s.ng, s.wo) > 0.0;
    if (!s.front_face) {
        s.ng = -s.ng;
        s.ns = -s.ns;
    }
    if (dot(s.ns, s.ng) <= 0.0) s.ns = s.ng;  // an interpolated normal pointing under the surface: fall back
    return s;
}

// The surface's tangents dp/du and dp/dv at s (for bump and normal maps), n the front face's shading
// normal. A triangle's come from its corners' positions and uvs (pbrt-v4's Triangle::InteractionFromIntersection);
// where its uvs are degenerate, any two tangents of n will do. A sphere's follow sphere_uv.
void surface_tangents(SurfaceHit s, vec3 n, out vec3 dpdu, out vec3 dpdv) {
    if (is_sphere(s.prim)) {
        vec4 sphere = geometry[GEOMETRY_ROWS * s.prim];
        vec3 d = (s.p - sphere.xyz) / sphere.w;
        float phi = atan(d.z, d.x), theta = acos(clamp(d.y, -1.0, 1.0));
        dpdu = sphere.w * 2.0 * PI * vec3(-sin(theta) * sin(phi), 0.0, sin(theta) * cos(phi));
        dpdv = sphere.w * PI * vec3(cos(theta) * cos(phi), -sin(theta), cos(theta) * sin(phi));
        return;
    }
    int i = GEOMETRY_ROWS * s.prim, j = SHADING_ROWS * s.prim;
    vec3 e1 = geometry[i + 1].xyz, e2 = geometry[i + 2].xyz;
    vec2 uv0 = vec2(shading[j].w, shading[j + 1].w), uv1 = vec2(shading[j + 2].w, shading[j + 3].x);
    vec2 uv2 = shading[j + 3].yz;
    vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    float det = d1.x * d2.y - d1.y * d2.x;
    if (abs(det) < 1e-12) {
        mat3 f = frame_around(n);
        dpdu = f[0];
        dpdv = f[1];
        return;
    }
    dpdu = (d2.y * e1 - d1.y * e2) / det;
    dpdv = (d1.x * e2 - d2.x * e1) / det;
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
