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
    int instance;    // Hit.instance: the instance whose group holds prim, or NO_INSTANCE
    bool front_face; // the ray arrived on the side the primitive's normal points to
};

#if HAS_INSTANCES
// A point and a direction of instance k's group space in the world, and a normal (by the inverse-transpose).
vec3 instance_point_to_world(int k, vec3 p) {
    int row = INSTANCE_ROWS * k + 5;
    vec4 r0 = instances[row], r1 = instances[row + 1], r2 = instances[row + 2];
    return vec3(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}

vec3 instance_vector_to_world(int k, vec3 v) {
    int row = INSTANCE_ROWS * k + 5;
    return vec3(dot(instances[row].xyz, v), dot(instances[row + 1].xyz, v), dot(instances[row + 2].xyz, v));
}

vec3 instance_normal_to_world(int k, vec3 n) {
    int row = INSTANCE_ROWS * k;
    return n.x * instances[row].xyz + n.y * instances[row + 1].xyz + n.z * instances[row + 2].xyz;
}

int instance_material(int k) { return floatBitsToInt(instances[INSTANCE_ROWS * k + 4].w); }
#endif

SurfaceHit surface_at(Ray ray, Hit hit) {
    SurfaceHit s;
    s.prim = hit.prim;
    s.instance = hit.instance;
#if HAS_INSTANCES
    s.material = hit.instance == NO_INSTANCE ? material_of(hit.prim) : instance_material(hit.instance);
#else
    s.material = material_of(hit.prim);
#endif
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
#if HAS_INSTANCES
        if (hit.instance != NO_INSTANCE) {  // the group's corners and normals are in its own space
            s.p = instance_point_to_world(hit.instance, s.p);
            s.ng = normalize(instance_normal_to_world(hit.instance, s.ng));
            n = instance_normal_to_world(hit.instance, n);
        }
#endif
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
#if HAS_INSTANCES
    if (s.instance != NO_INSTANCE) {
        dpdu = instance_vector_to_world(s.instance, dpdu);
        dpdv = instance_vector_to_world(s.instance, dpdv);
    }
#endif
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
