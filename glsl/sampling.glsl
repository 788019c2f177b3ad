// Warping uniform random numbers onto the shapes we integrate over. Each function's pdf is stated beside it.

// Shirley-Chiu concentric mapping of [0,1)^2 onto the unit disk: area-preserving, low distortion, so a
// stratified (Sobol) pattern stays stratified on the lens. pdf = 1 / pi per unit area. This and
// sample_polygon have numpy twins in app/lenslab/optics/aperture.py (the camera's rays on the host).
vec2 sample_concentric_disk(vec2 u) {
    vec2 o = 2.0 * u - 1.0;
    if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
    float r, theta;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        theta = (PI / 4.0) * (o.y / o.x);
    } else {
        r = o.y;
        theta = (PI / 2.0) - (PI / 4.0) * (o.x / o.y);
    }
    return r * vec2(cos(theta), sin(theta));
}

// Uniform point on a regular polygon with `blades` corners inscribed in the unit circle, one corner at angle
// `rotation`: pick one of the equal triangles (centre, corner k, corner k+1), then a uniform point in it.
vec2 sample_polygon(vec2 u, int blades, float rotation) {
    float n = float(blades);
    float k = min(floor(u.x * n), n - 1.0);
    float v = u.x * n - k;  // reuse the remainder of u.x as a fresh uniform number
    float a0 = rotation + 2.0 * PI * k / n;
    float a1 = rotation + 2.0 * PI * (k + 1.0) / n;
    vec2 p0 = vec2(cos(a0), sin(a0));
    vec2 p1 = vec2(cos(a1), sin(a1));
    float su = sqrt(v);  // uniform barycentrics on the triangle (0, p0, p1)
    return su * ((1.0 - u.y) * p0 + u.y * p1);
}

// Cosine-weighted direction about +Z (Malley's method). pdf = cos(theta) / pi.
vec3 sample_cosine_hemisphere(vec2 u) {
    vec2 d = sample_concentric_disk(u);
    return vec3(d, sqrt(max(0.0, 1.0 - dot(d, d))));
}

// Uniform direction on the unit sphere. pdf = 1 / (4 pi).
vec3 sample_uniform_sphere(vec2 u) {
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// Uniform direction inside a cone about +Z, given 1 - cos(theta_max) (passed as such to keep precision for
// tiny cones). pdf = 1 / (2 pi (1 - cos theta_max)).
vec3 sample_uniform_cone(vec2 u, float one_minus_cos_max) {
    float one_minus_cos = u.x * one_minus_cos_max;
    float cos_theta = 1.0 - one_minus_cos;
    float sin_theta = sqrt(max(0.0, one_minus_cos * (2.0 - one_minus_cos)));
    float phi = 2.0 * PI * u.y;
    return vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// Uniform barycentrics (b1, b2) on a triangle (Heitz 2019's low-distortion map would also do).
vec2 sample_triangle(vec2 u) {
    float su = sqrt(u.x);
    return vec2(su * (1.0 - u.y), su * u.y);
}

float power_heuristic(float pdf_a, float pdf_b) {
    float a = pdf_a * pdf_a;
    float b = pdf_b * pdf_b;
    return (a + b) > 0.0 ? a / (a + b) : 0.0;
}

// An orthonormal frame around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
mat3 frame_around(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
    return mat3(t, bt, n);
}
