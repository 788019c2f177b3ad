// Next-event estimation: choose a light in proportion to its power, then a point or direction on it.
// Every pdf here is with respect to solid angle at the shading point and includes the selection
// probability, so that MIS against BSDF sampling compares like with like.

struct LightSample {
    vec3 wi;
    vec3 radiance;
    float pdf;
    float dist;  // INFINITY for the environment
};

// The emissive primitive whose cumulative pmf first exceeds u (binary search over the light table).
int pick_light(float u) {
    int lo = 0, hi = light_count - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (lights[mid].y <= u) lo = mid + 1; else hi = mid;
    }
    return floatBitsToInt(lights[lo].x);
}

// 1 - cos(theta_max) of the cone a sphere subtends from distance d > r, precise for tiny cones.
float sphere_cone_one_minus_cos(float r, float d) {
    float sin2 = (r * r) / (d * d);
    return sin2 / (1.0 + sqrt(max(0.0, 1.0 - sin2)));
}

float triangle_area(int prim) {
    return 0.5 * length(cross(geometry[3 * prim + 1].xyz, geometry[3 * prim + 2].xyz));
}

// Density (solid angle, selection included) of reaching point q with normal nq on emissive prim from p.
float area_light_pdf(int prim, vec3 p, vec3 q, vec3 nq) {
    float pmf = light_pmf_of(prim);
    if (pmf <= 0.0) return 0.0;
    vec3 to_q = q - p;
    float dist2 = dot(to_q, to_q);
    if (is_sphere(prim)) {
        vec4 sphere = geometry[3 * prim];
        float dc = distance(p, sphere.xyz);
        if (dc > sphere.w * 1.0001) return pmf / (2.0 * PI * sphere_cone_one_minus_cos(sphere.w, dc));
        float cos_l = abs(dot(nq, to_q)) / sqrt(dist2);
        return cos_l > 0.0 ? pmf * dist2 / (cos_l * 4.0 * PI * sphere.w * sphere.w) : 0.0;
    }
    float cos_l = abs(dot(nq, to_q)) / sqrt(dist2);
    return cos_l > 0.0 ? pmf * dist2 / (cos_l * triangle_area(prim)) : 0.0;
}

float environment_pdf(vec3 dir) { return env_select_pmf * (0.25 * INV_PI); }

vec3 environment_radiance(vec3 dir) { return env_radiance; }

// Sample a point on the chosen emissive primitive as seen from p.
bool sample_area_light(int prim, vec3 p, vec3 u3, out LightSample ls) {
    vec3 q, nq;
    if (is_sphere(prim)) {
        vec4 sphere = geometry[3 * prim];
        vec3 axis = sphere.xyz - p;
        float dc = length(axis);
        if (dc > sphere.w * 1.0001) {  // outside: sample the cone of directions the sphere subtends
            float omc = sphere_cone_one_minus_cos(sphere.w, dc);
            vec3 local = sample_uniform_cone(u3.xy, omc);
            vec3 dir = frame_around(axis / dc) * local;
            float cos_t = local.z;
            float sin2_t = max(0.0, 1.0 - cos_t * cos_t);
            float t = dc * cos_t - sqrt(max(0.0, sphere.w * sphere.w - dc * dc * sin2_t));
            q = p + t * dir;
        } else {  // inside: uniform over the area
            q = sphere.xyz + sphere.w * sample_uniform_sphere(u3.xy);
        }
        nq = normalize(q - sphere.xyz);
    } else {
        vec2 b = sample_triangle(u3.xy);
        vec3 e1 = geometry[3 * prim + 1].xyz, e2 = geometry[3 * prim + 2].xyz;
        q = geometry[3 * prim].xyz + b.x * e1 + b.y * e2;
        nq = normalize(cross(e1, e2));
    }
    vec3 to_q = q - p;
    ls.dist = length(to_q);
    if (ls.dist <= 0.0) return false;
    ls.wi = to_q / ls.dist;
    bool front = dot(nq, -ls.wi) > 0.0;
    ls.radiance = emitted_radiance(material_of(prim), front);
    ls.pdf = area_light_pdf(prim, p, q, nq);
    return ls.pdf > 0.0 && max_component(ls.radiance) > 0.0;
}

bool sample_light(vec3 p, vec4 u, out LightSample ls) {
    if (u.x < env_select_pmf) {
        ls.wi = sample_uniform_sphere(u.yz);
        ls.radiance = environment_radiance(ls.wi);
        ls.pdf = environment_pdf(ls.wi);
        ls.dist = INFINITY;
        return ls.pdf > 0.0 && max_component(ls.radiance) > 0.0;
    }
    if (light_count == 0) return false;
    // The table's cumulative pmf runs from 0 to 1 - env_select_pmf (the environment's share is not in it),
    // so u.x shifted past that share picks an area light with exactly its stored pmf.
    return sample_area_light(pick_light(u.x - env_select_pmf), p, u.yzw, ls);
}
