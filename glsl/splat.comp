#version 430
// Gaussian pixel filter by splatting, done as a gather so that no two invocations write the same pixel
// (no atomics) and every pixel adds its terms in one fixed order (the same image however the work is split).
//
// trace.comp has written one radiance sample per slot for samples sample_start ... of every pixel, each taken
// at a position uniform over its pixel. A sample at x lends its radiance to every pixel q whose filter
// reaches it, weighted by g(x - centre of q) with g(d) = exp(-|d|^2 / 2 stddev^2) truncated at 4 stddev per
// axis (Mitsuba's gaussian). Pixel q gathers those terms from its neighbours' samples, whose positions in
// their pixels trace.comp stored beside their radiance.
//
// The estimate of the filtered image at q is sum(g L) / (N * G(q)), where G(q) is the integral of g over the
// part of the image the filter covers (all of it inside, less at the borders, where no samples are taken):
// the expected sum of weights, so the estimate is unbiased. With sampled_weights the divisor is instead the
// sum of the weights the samples drew, as Mitsuba's film does: a ratio estimator, consistent but biased by
// O(1/N), with less noise where the image is smooth (a user's choice: RenderSettings.filter_weights).
// The film's alpha channel gathers the divisor, so resolve stays "rgb / alpha" and partial renders still
// merge by adding.

layout(local_size_x = LOCAL_SIZE_X) in;

layout(std430, binding = ACCUMULATION_BINDING) readonly buffer Samples { vec4 samples[]; };  // trace.comp's slots
layout(std430, binding = SPLAT_IMAGE_BINDING) buffer Accumulation { vec4 accumulation[]; };

uniform ivec2 image_size;
uniform int tile_start;  // first pixel (row-major index) of this dispatch
uniform int tile_pixels;
uniform int sample_count;  // slot layers
uniform float filter_stddev;
uniform bool sampled_weights;

const float SQRT_HALF_PI = 1.25331413731550025;

float erf_approx(float x) {  // Abramowitz & Stegun 7.1.26, |error| < 1.5e-7
    float t = 1.0 / (1.0 + 0.3275911 * abs(x));
    float poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    return sign(x) * (1.0 - poly * exp(-x * x));
}

// Integral of g along one axis over the image [0, size] for a filter centred at `centre`.
float covered_weight(float centre, float size) {
    float radius = 4.0 * filter_stddev;
    float lo = max(-centre, -radius), hi = min(size - centre, radius);
    float s = filter_stddev * sqrt(2.0);
    return filter_stddev * SQRT_HALF_PI * (erf_approx(hi / s) - erf_approx(lo / s));
}

// The inverse of trace.comp's encode_pixel_position, at the centre of the 1/4096-pixel bucket in x.
vec2 decode_pixel_position(float e) { return vec2((floor(e) + 0.5) / 4096.0, fract(e)); }

float filter_1d(float d) {
    return abs(d) <= 4.0 * filter_stddev ? exp(-d * d / (2.0 * filter_stddev * filter_stddev)) : 0.0;
}

void main() {
    int local = int(gl_GlobalInvocationID.x);
    if (local >= tile_pixels) return;
    int q = tile_start + local;
    ivec2 pixel = ivec2(q % image_size.x, q / image_size.x);
    vec2 centre = vec2(pixel) + 0.5;
    int pixels = image_size.x * image_size.y;
    int reach = int(ceil(4.0 * filter_stddev + 0.5));
    ivec2 lo = max(pixel - reach, ivec2(0)), hi = min(pixel + reach, image_size - 1);
    float expected_weight = covered_weight(centre.x, float(image_size.x)) *
                            covered_weight(centre.y, float(image_size.y));

    vec4 sum = accumulation[q];
    for (int k = 0; k < sample_count; k++) {
        vec3 gathered = vec3(0.0);
        float drawn_weight = 0.0;
        for (int y = lo.y; y <= hi.y; y++) {
            for (int x = lo.x; x <= hi.x; x++) {
                vec4 s = samples[k * pixels + y * image_size.x + x];
                vec2 d = vec2(x, y) + decode_pixel_position(s.w) - centre;
                float w = filter_1d(d.x) * filter_1d(d.y);
                if (w > 0.0) {
                    gathered += w * s.xyz;
                    drawn_weight += w;
                }
            }
        }
        sum += vec4(gathered, sampled_weights ? drawn_weight : expected_weight);
    }
    accumulation[q] = sum;
}
