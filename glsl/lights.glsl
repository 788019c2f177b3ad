// Next-event estimation: choose a light in proportion to its power, then a point or direction on it.
// Every pdf here is with respect to solid angle at the shading point and includes the selection
// probability, so that MIS against BSDF sampling compares like with like.
//
// The light table (render/buffers.py) holds three vec4 per light:
//   (type, primitive index as float bits, cumulative pmf, pmf), (position | direction, cos theta_max), (rgb, -).

const int LIGHT_AREA = 0;
const int LIGHT_POINT = 1;
const int LIGHT_SUN = 2;
const int LIGHT_ENVIRONMENT = 3;

uniform int env_type;           // 0: constant (env_radiance), 1: lat-long map
uniform float env_strength;
uniform int env_texture;        // the map's texture record
uniform float env_rotation;     // radians about +Y
uniform int env_dist_offset;    // sampling tables in image_data (render/environment.py)
uniform ivec2 env_size;           // the map's pixels
uniform ivec2 env_table_size;     // cells of its sampling tables (at most 1024 x 512)
uniform int env_rows_pole_to_pole; // 1: image row i lies at polar angle pi i / (H - 1) (Mitsuba's layout)
uniform vec3 sun_direction;     // towards the sun
uniform float sun_one_minus_cos; // 1 - cos of the disk's angular radius (host-computed: precise); 0: delta
uniform vec3 sun_radiance;
uniform float sun_pmf;

struct LightSample {
    vec3 wi;
    vec3 radiance;
    float pdf;
    float dist;  // INFINITY for lights at infinity
    bool delta;  // a point or a sun of zero size: no BSDF sample can hit it, no MIS
};

// The light whose cumulative pmf first exceeds u (binary search over the table).
int pick_light(float u) {
    int lo = 0, hi = light_count - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (lights[3 * mid].z <= u) lo = mid + 1; else hi = mid;
    }
    return lo;
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

// -- the environment ----------------------------------------------------------------------------------
vec2 environment_uv(vec3 d) {
    float phi = atan(d.x, -d.z) - env_rotation;
    return vec2(fract(0.5 + phi * (0.5 * INV_PI)), acos(clamp(d.y, -1.0, 1.0)) * INV_PI);
}

vec3 environment_direction(vec2 uv) {
    float phi = (uv.x - 0.5) * 2.0 * PI + env_rotation;
    float theta = uv.y * PI;
    float s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

float env_table(int i) { return uintBitsToFloat(image_data[env_dist_offset + i]); }

vec3 environment_radiance(vec3 dir) {
    if (HAS_ENVIRONMENT_MAP == 0 || env_type == 0) return env_radiance;
    vec2 uv = environment_uv(dir);
    float h = float(env_size.y);
    if (env_rows_pole_to_pole != 0) {
        uv.y = (uv.y * (h - 1.0) + 0.5) / h;  // the texture lookup puts row i at (i + 1/2) / H: move there
    } else {
        uv.y = clamp(uv.y, 0.5 / h, 1.0 - 0.5 / h);  // textures repeat; a pole must not blend in the other
    }
    // The sampling tables stay on the centred rows: their pdf reaches one row beyond each pixel (see
    // render/environment.py), which covers the half-row shift, so sampling stays unbiased.
    return env_strength * texture_rgb(env_texture, vec2(uv.x, 1.0 - uv.y));  // row 0 is the top
}

float environment_pdf(vec3 dir) {
    if (env_select_pmf <= 0.0) return 0.0;
    if (HAS_ENVIRONMENT_MAP == 0 || env_type == 0) return env_select_pmf * (0.25 * INV_PI);
    vec2 uv = environment_uv(dir);
    float sin_theta = sin(uv.y * PI);
    if (sin_theta <= 0.0) return 0.0;
    int w = env_table_size.x, h = env_table_size.y;
    int row = min(int(uv.y * float(h)), h - 1), col = min(int(uv.x * float(w)), w - 1);
    float pdf_uv = env_table((h + 1) + h * (w + 1) + row * w + col);
    return env_select_pmf * pdf_uv / (2.0 * PI * PI * sin_theta);
}

// First index i in [first, first + count) with table[i + 1] > u, for a cumulative table starting at 0.
int search_cdf(int first, int count, float u) {
    int lo = 0, hi = count - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (env_table(first + mid + 1) <= u) lo = mid + 1; else hi = mid;
    }
    return lo;
}

vec3 sample_environment_direction(vec2 u) {
    if (HAS_ENVIRONMENT_MAP == 0 || env_type == 0) return sample_uniform_sphere(u);
    int w = env_table_size.x, h = env_table_size.y;
    int row = search_cdf(0, h, u.y);
    float r0 = env_table(row), r1 = env_table(row + 1);
    float v = (float(row) + (u.y - r0) / max(r1 - r0, 1e-12)) / float(h);
    int base = (h + 1) + row * (w + 1);
    int col = search_cdf(base, w, u.x);
    float c0 = env_table(base + col), c1 = env_table(base + col + 1);
    float uu = (float(col) + (u.x - c0) / max(c1 - c0, 1e-12)) / float(w);
    return environment_direction(vec2(uu, clamp(v, 0.0, 1.0)));
}

// -- the sun ------------------------------------------------------------------------------------------
// Radiance of the sun's disk seen along dir, for rays that escape the scene (zero for a delta sun).
vec3 sun_seen(vec3 dir) {
    return (HAS_SUN != 0 && sun_one_minus_cos > 0.0 && 1.0 - dot(dir, sun_direction) <= sun_one_minus_cos) ? sun_radiance : vec3(0.0);
}

float sun_pdf() { return HAS_SUN != 0 && sun_one_minus_cos > 0.0 ? sun_pmf / (2.0 * PI * sun_one_minus_cos) : 0.0; }

// -- sampling any light -------------------------------------------------------------------------------
bool sample_area_light(int prim, vec3 p, vec2 u, out LightSample ls) {
    ls.delta = false;  // `out` starts undefined: every field must be written
    vec3 q, nq;
    if (is_sphere(prim)) {
        vec4 sphere = geometry[3 * prim];
        vec3 axis = sphere.xyz - p;
        float dc = length(axis);
        if (dc > sphere.w * 1.0001) {  // outside: sample the cone of directions the sphere subtends
            vec3 local = sample_uniform_cone(u, sphere_cone_one_minus_cos(sphere.w, dc));
            vec3 dir = frame_around(axis / dc) * local;
            float sin2_t = max(0.0, 1.0 - local.z * local.z);
            float t = dc * local.z - sqrt(max(0.0, sphere.w * sphere.w - dc * dc * sin2_t));
            q = p + t * dir;
        } else {  // inside: uniform over the area
            q = sphere.xyz + sphere.w * sample_uniform_sphere(u);
        }
        nq = normalize(q - sphere.xyz);
    } else {
        vec2 b = sample_triangle(u);
        vec3 e1 = geometry[3 * prim + 1].xyz, e2 = geometry[3 * prim + 2].xyz;
        q = geometry[3 * prim].xyz + b.x * e1 + b.y * e2;
        nq = normalize(cross(e1, e2));
    }
    vec3 to_q = q - p;
    ls.dist = length(to_q);
    if (ls.dist <= 0.0) return false;
    ls.wi = to_q / ls.dist;
    ls.radiance = emitted_radiance(material_of(prim), dot(nq, -ls.wi) > 0.0);
    ls.pdf = area_light_pdf(prim, p, q, nq);
    return ls.pdf > 0.0 && max_component(ls.radiance) > 0.0;
}

bool sample_light(vec3 p, vec4 u, out LightSample ls) {
    ls.delta = false;
    ls.dist = INFINITY;
    if (light_count == 0) return false;
    int i = pick_light(u.x);
    vec4 l0 = lights[3 * i], l1 = lights[3 * i + 1], l2 = lights[3 * i + 2];
    int type = int(l0.x);
    if (HAS_AREA_LIGHTS != 0 && type == LIGHT_AREA) return sample_area_light(floatBitsToInt(l0.y), p, u.yz, ls);
    if (HAS_POINT_LIGHTS != 0 && type == LIGHT_POINT) {
        vec3 to_l = l1.xyz - p;
        float d2 = dot(to_l, to_l);
        ls.dist = sqrt(d2);
        ls.wi = to_l / ls.dist;
        ls.radiance = l2.xyz / d2;  // intensity falls off with the square of the distance
        ls.pdf = l0.w;
        ls.delta = true;
        return d2 > 0.0;
    }
    if (HAS_SUN != 0 && type == LIGHT_SUN) {
        if (sun_one_minus_cos <= 0.0) {
            ls.wi = sun_direction;
            ls.radiance = sun_radiance;  // a delta sun carries its irradiance
            ls.pdf = l0.w;
            ls.delta = true;
            return true;
        }
        ls.wi = frame_around(sun_direction) * sample_uniform_cone(u.yz, sun_one_minus_cos);
        ls.radiance = sun_radiance;
        ls.pdf = sun_pdf();
        return true;
    }
    if (HAS_ENVIRONMENT_LIGHT == 0) return false;
    ls.wi = sample_environment_direction(u.yz);
    ls.radiance = environment_radiance(ls.wi);
    ls.pdf = environment_pdf(ls.wi);
    return ls.pdf > 0.0 && max_component(ls.radiance) > 0.0;
}
