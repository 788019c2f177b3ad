// Next-event estimation: choose a light (see "Choosing a light" below), then a point or direction on it.
// Every pdf here is with respect to solid angle at the shading point and includes the probability of
// choosing the light, so that MIS against BSDF sampling compares like with like.
//
// The light table (render/buffers.py) holds LIGHT_ROWS (three) vec4 per light:
//   (type, primitive index as float bits, cumulative power share, power share), (position | direction, -),
//   (rgb, -). The type is one of LIGHT_AREA, LIGHT_POINT, LIGHT_SPOT, LIGHT_SUN, LIGHT_ENVIRONMENT
//   (render/gpu_layout.py). A spot holds cos(cutoff) and cos(beam) in rows 1 and 2's w, and in row 0's second
//   slot the offset of its other parameters in image_data (spot_intensity).

uniform int env_type;           // ENV_CONSTANT (env_radiance) or ENV_MAP (a lat-long map)
uniform float env_strength;
uniform int env_texture;        // the map's texture record
uniform mat3 env_world_to_map;  // world directions into the panorama's own frame (a rotation: its transpose
                                // takes them back); render/environment.py
uniform int env_dist_offset;    // sampling tables in image_data (render/environment.py)
uniform ivec2 env_size;           // the map's pixels
uniform ivec2 env_table_size;     // cells of its sampling tables (at most 1024 x 512)
uniform int env_rows_pole_to_pole; // 1: image row i lies at polar angle pi i / (H - 1) (Mitsuba's layout)
uniform vec3 sun_direction;     // towards the sun
uniform float sun_one_minus_cos; // 1 - cos of the disk's angular radius (host-computed: precise); 0: delta
uniform vec3 sun_radiance;
uniform int env_light;          // the environment's row in the light table; -1: it lights nothing directly
uniform int sun_light;          // the sun's row, or -1
uniform int lights_at_point;    // 1: choose lights by what they bring to the shading point (the general kernel asks)

struct LightSample {
    vec3 wi;
    vec3 radiance;
    float pdf;
    float dist;  // INFINITY for lights at infinity
    bool delta;  // a point or a sun of zero size: no BSDF sample can hit it, no MIS
};

// -- Choosing a light ----------------------------------------------------------------------------------
// By power alone (a binary search of the cumulative table) is cheap and blind to where the shading point
// is: a lamp beside the subject and a sky whose power is measured over the whole scene compete by their
// totals, and in a large scene the sky takes most shadow rays while the lamp that lights the subject stays
// noisy. With few lights (buffers.py's LIGHTS_AT_POINT_LIMIT) the choice is instead proportional to a rough
// estimate of the irradiance each light brings to the shading point: its power over the squared distance
// to it (never less than its own extent), or a constant for light from infinity; no occlusion and no
// cosines, as in the importance of pbrt-v4's light BVH. Each point then has a distribution of its own, so
// MIS must recompute the probability at the point a BSDF sample left from (light_choice_pmf). Every light
// that could reach the point keeps a nonzero probability: both choices are unbiased.

bool choosing_at_point() {
    return HAS_LIGHTS_AT_POINT != 0 && (HAS_LIGHTS_BY_POWER == 0 || lights_at_point != 0);
}

// What the choice reads, in a uniform block (render/buffers.py's light_choice array): every lane reads the
// same light at the same time, which uniform blocks serve best. It holds LIGHT_PLACES lights.
layout(std140, binding = LIGHT_CHOICE_BINDING) uniform LightPlaces {
    vec4 light_place[LIGHT_PLACES];     // (centre, reach^2); reach^2 < 0: at infinity
    vec4 light_scale[LIGHT_PLACES / 4]; // power share x falloff, four lights to a vec4
};

// Light i's weight at p: roughly the irradiance it brings there (render/buffers.py's _LightEntry).
float light_weight_at(int i, vec3 p) {
    vec4 where = light_place[i];
    float scale = light_scale[i >> 2][i & 3];
    vec3 d = where.xyz - p;
    return scale / (where.w < 0.0 ? 1.0 : max(dot(d, d), where.w));
}

// The probability that next-event estimation at p chooses light i (-1: no light, probability 0), where
// `weights` is the sum of all lights' weights there (LightChoice.weights).
float light_choice_pmf(int i, vec3 p, float weights) {
    if (i < 0) return 0.0;
    if (choosing_at_point()) return weights > 0.0 ? light_weight_at(i, p) / weights : 0.0;
    return lights[LIGHT_ROWS * i].w;
}

// The light whose cumulative power share first exceeds u (binary search over the table).
int pick_light(float u) {
    int lo = 0, hi = light_count - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (lights[LIGHT_ROWS * mid].z <= u) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// Next-event estimation's choice at a shading point: the light (-1: none), the probability of choosing
// it, and the sum of all lights' weights there, which MIS needs later (light_choice_pmf).
struct LightChoice {
    int light;
    float pmf;
    float weights;
};

LightChoice choose_light(vec3 p, float u) {
    LightChoice c;
    c.light = -1;
    c.pmf = 0.0;
    c.weights = 1.0;
    if (light_count == 0) return c;
    if (choosing_at_point()) {
        // One pass, as a weighted reservoir of one: light i takes the place of the choice so far with
        // probability w_i / (w_0 + ... + w_i), which leaves each light chosen with probability w_i / total.
        // The one random number serves every step, rescaled to [0, 1) after each (as pbrt-v4's
        // SampleDiscrete remaps it). The loop runs alike in all lanes, so the table reads are uniform.
        float total = 0.0, chosen_weight = 0.0;
        for (int i = 0; i < light_count; i++) {
            float w = light_weight_at(i, p);
            total += w;
            float q = total > 0.0 ? w / total : 0.0;
            if (u < q) {
                c.light = i;
                chosen_weight = w;
                u = min(u / q, ONE_MINUS_EPSILON);
            } else {
                u = min((u - q) / (1.0 - q), ONE_MINUS_EPSILON);
            }
        }
        c.weights = total;
        c.pmf = total > 0.0 ? chosen_weight / total : 0.0;
    } else {
        c.light = pick_light(u);
        c.pmf = light_choice_pmf(c.light, p, c.weights);
    }
    return c;
}

// 1 - cos(theta_max) of the cone a sphere subtends from distance d > r, precise for tiny cones.
float sphere_cone_one_minus_cos(float r, float d) {
    float sin2 = (r * r) / (d * d);
    return sin2 / (1.0 + sqrt(max(0.0, 1.0 - sin2)));
}

float triangle_area(int prim) {
    return 0.5 * length(cross(geometry[GEOMETRY_ROWS * prim + 1].xyz, geometry[GEOMETRY_ROWS * prim + 2].xyz));
}

// Density (solid angle) of reaching point q with normal nq on emissive prim from p, where `pmf` is the
// probability of having chosen the prim's light.
float area_light_pdf(int prim, vec3 p, vec3 q, vec3 nq, float pmf) {
    if (pmf <= 0.0) return 0.0;
    vec3 to_q = q - p;
    float dist2 = dot(to_q, to_q);
    if (is_sphere(prim)) {
        vec4 sphere = geometry[GEOMETRY_ROWS * prim];
        float dc = distance(p, sphere.xyz);
        if (dc > sphere.w * 1.0001) return pmf / (2.0 * PI * sphere_cone_one_minus_cos(sphere.w, dc));
        float cos_l = abs(dot(nq, to_q)) / sqrt(dist2);
        return cos_l > 0.0 ? pmf * dist2 / (cos_l * 4.0 * PI * sphere.w * sphere.w) : 0.0;
    }
    float cos_l = abs(dot(nq, to_q)) / sqrt(dist2);
    return cos_l > 0.0 ? pmf * dist2 / (cos_l * triangle_area(prim)) : 0.0;
}

// -- the environment ----------------------------------------------------------------------------------
// The lat-long mapping works in the panorama's own frame; the lookup, the pdf and the sampling below all
// pass through these two, so any rotation of the map keeps them consistent (a rotation keeps solid angle).
vec2 environment_uv(vec3 world_dir) {
    vec3 d = env_world_to_map * world_dir;
    float phi = atan(d.x, -d.z);
    return vec2(fract(0.5 + phi * (0.5 * INV_PI)), acos(clamp(d.y, -1.0, 1.0)) * INV_PI);
}

vec3 environment_direction(vec2 uv) {
    float phi = (uv.x - 0.5) * 2.0 * PI;
    float theta = uv.y * PI;
    float s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi)) * env_world_to_map;  // the transpose: back to the world
}

float env_table(int i) { return uintBitsToFloat(image_data[env_dist_offset + i]); }

vec3 environment_radiance(vec3 dir) {
    if (HAS_ENVIRONMENT_MAP == 0 || env_type == ENV_CONSTANT) return env_radiance;
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

// Density (solid angle) of sampling dir from the environment, chosen with probability `pmf`.
float environment_pdf(vec3 dir, float pmf) {
    if (pmf <= 0.0) return 0.0;
    if (HAS_ENVIRONMENT_MAP == 0 || env_type == ENV_CONSTANT) return pmf * (0.25 * INV_PI);
    vec2 uv = environment_uv(dir);
    float sin_theta = sin(uv.y * PI);
    if (sin_theta <= 0.0) return 0.0;
    int w = env_table_size.x, h = env_table_size.y;
    int row = min(int(uv.y * float(h)), h - 1), col = min(int(uv.x * float(w)), w - 1);
    float pdf_uv = env_table((h + 1) + h * (w + 1) + row * w + col);
    return pmf * pdf_uv / (2.0 * PI * PI * sin_theta);
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
    if (HAS_ENVIRONMENT_MAP == 0 || env_type == ENV_CONSTANT) return sample_uniform_sphere(u);
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

// -- spots --------------------------------------------------------------------------------------------
// Mitsuba 3's spot (src/emitters/spot.cpp): full intensity within the beam, then linear in the angle down to
// zero at the cutoff, times an optional texture projected through the cone (scene/lights.py's SpotLight).
float spot_param(int at, int i) { return uintBitsToFloat(image_data[at + i]); }
vec3 spot_vector(int at, int i) { return vec3(spot_param(at, i), spot_param(at, i + 1), spot_param(at, i + 2)); }

// The radiant intensity (W/sr) spot light (l0, l1, l2) sends along the unit direction dir, away from it.
vec3 spot_intensity(vec4 l0, vec4 l1, vec4 l2, vec3 dir) {
    int at = floatBitsToInt(l0.y);  // SPOT_PARAMS floats: axis, right, top, cutoff, slope, 1/(2 tan cutoff), texture
    float cos_theta = dot(spot_vector(at, 0), dir);
    if (cos_theta <= l1.w) return vec3(0.0);  // at or beyond the cutoff
    float falloff = cos_theta >= l2.w ? 1.0 : (spot_param(at, 9) - acos(cos_theta)) * spot_param(at, 10);
    vec3 intensity = l2.xyz * falloff;
    int tex = int(spot_param(at, 12));
    if (tex >= 0) {  // the slide: u along right, v along top, over the square the cutoff's tangent spans
        vec2 across = vec2(dot(spot_vector(at, 3), dir), dot(spot_vector(at, 6), dir));
        intensity *= texture_rgb(tex, 0.5 + across * (spot_param(at, 11) / cos_theta));
    }
    return intensity;
}

// -- the sun ------------------------------------------------------------------------------------------
// Radiance of the sun's disk seen along dir, for rays that escape the scene (zero for a delta sun).
vec3 sun_seen(vec3 dir) {
    return (HAS_SUN != 0 && sun_one_minus_cos > 0.0 && 1.0 - dot(dir, sun_direction) <= sun_one_minus_cos) ? sun_radiance : vec3(0.0);
}

// Density (solid angle) of sampling a direction in the sun's disk, the sun chosen with probability `pmf`.
float sun_pdf(float pmf) { return HAS_SUN != 0 && sun_one_minus_cos > 0.0 ? pmf / (2.0 * PI * sun_one_minus_cos) : 0.0; }

// -- sampling any light -------------------------------------------------------------------------------
bool sample_area_light(int prim, vec3 p, vec2 u, float pmf, out LightSample ls) {
    ls.delta = false;  // `out` starts undefined: every field must be written
    vec3 q, nq;
    if (is_sphere(prim)) {
        vec4 sphere = geometry[GEOMETRY_ROWS * prim];
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
        vec3 e1 = geometry[GEOMETRY_ROWS * prim + 1].xyz, e2 = geometry[GEOMETRY_ROWS * prim + 2].xyz;
        q = geometry[GEOMETRY_ROWS * prim].xyz + b.x * e1 + b.y * e2;
        nq = normalize(cross(e1, e2));
    }
    vec3 to_q = q - p;
    ls.dist = length(to_q);
    if (ls.dist <= 0.0) return false;
    ls.wi = to_q / ls.dist;
    ls.radiance = emitted_radiance(material_of(prim), dot(nq, -ls.wi) > 0.0);
    ls.pdf = area_light_pdf(prim, p, q, nq, pmf);
    return ls.pdf > 0.0 && max_component(ls.radiance) > 0.0;
}

// A sample of the chosen light for the shading point p.
bool sample_light(vec3 p, LightChoice choice, vec2 u, out LightSample ls) {
    ls.delta = false;
    ls.dist = INFINITY;
    float pmf = choice.pmf;
    if (pmf <= 0.0) return false;
    int i = choice.light;
    vec4 l0 = lights[LIGHT_ROWS * i], l1 = lights[LIGHT_ROWS * i + 1], l2 = lights[LIGHT_ROWS * i + 2];
    int type = int(l0.x);
    if (HAS_AREA_LIGHTS != 0 && type == LIGHT_AREA) return sample_area_light(floatBitsToInt(l0.y), p, u, pmf, ls);
    if (HAS_POINT_LIGHTS != 0 && type == LIGHT_POINT) {
        vec3 to_l = l1.xyz - p;
        float d2 = dot(to_l, to_l);
        ls.dist = sqrt(d2);
        ls.wi = to_l / ls.dist;
        ls.radiance = l2.xyz / d2;  // intensity falls off with the square of the distance
        ls.pdf = pmf;
        ls.delta = true;
        return d2 > 0.0;
    }
    if (HAS_SPOT_LIGHTS != 0 && type == LIGHT_SPOT) {
        vec3 to_l = l1.xyz - p;
        float d2 = dot(to_l, to_l);
        if (!(d2 > 0.0)) return false;
        ls.dist = sqrt(d2);
        ls.wi = to_l / ls.dist;
        ls.radiance = spot_intensity(l0, l1, l2, -ls.wi) / d2;
        ls.pdf = pmf;
        ls.delta = true;
        return max_component(ls.radiance) > 0.0;
    }
    if (HAS_SUN != 0 && type == LIGHT_SUN) {
        if (sun_one_minus_cos <= 0.0) {
            ls.wi = sun_direction;
            ls.radiance = sun_radiance;  // a delta sun carries its irradiance
            ls.pdf = pmf;
            ls.delta = true;
            return true;
        }
        ls.wi = frame_around(sun_direction) * sample_uniform_cone(u, sun_one_minus_cos);
        ls.radiance = sun_radiance;
        ls.pdf = sun_pdf(pmf);
        return true;
    }
    if (HAS_ENVIRONMENT_LIGHT == 0) return false;
    ls.wi = sample_environment_direction(u);
    ls.radiance = environment_radiance(ls.wi);
    ls.pdf = environment_pdf(ls.wi, pmf);
    return ls.pdf > 0.0 && max_component(ls.radiance) > 0.0;
}
