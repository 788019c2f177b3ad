#version 430
// Entry kernel of the progressive renderer: one invocation per pixel of a tile of consecutive pixels,
// taking `sample_count` samples (sample indices sample_start ...) of that pixel.
//
// Two ways to turn samples into pixels (docs/architecture.md, "Rendering"):
// * splat_pixels == 0: each sample lands in its own pixel. The sum is loaded once and each sample added in
//   index order, so the image is bit-identical however the host splits the work into dispatches. A box
//   filter, or a gaussian by filter importance sampling.
// * splat_pixels > 0: a gaussian filter by splatting (as Mitsuba and pbrt-v3). Samples are uniform over their
//   pixel and their radiance and position are written to a slot of their own; splat.comp then spreads every sample over
//   the pixels its filter reaches. Every sample serves several pixels, so the noise per pixel is lower.

layout(local_size_x = LOCAL_SIZE_X) in;

#include "common.glsl"
#include "rng.glsl"
#include "sampling.glsl"
#include "camera.glsl"
#include "intersect.glsl"
#include "textures.glsl"
#include "texcoords.glsl"
#include "mask.glsl"
#include "bsp.glsl"
#include "surface.glsl"
#include "microfacet.glsl"
#include "bsdf.glsl"
#include "lights.glsl"
#include "feature_buffers.glsl"
#include "integrator.glsl"

// splat_pixels == 0: rgb = sum of radiance samples, a = their count (the film's accumulation).
// splat_pixels > 0: one sample per slot, slot = (sample index - sample_start) * splat_pixels + pixel: its
// radiance, and where in the pixel it was taken (encode_pixel_position).
layout(std430, binding = ACCUMULATION_BINDING) buffer Accumulation { vec4 accumulation[]; };
#if HAS_FEATURE_BUFFERS
// The denoiser's guides (feature_buffers.glsl), FEATURE_ROWS vec4 per pixel: (albedo sum, samples), (normal
// sum, 0). Each sample adds to the pixel it was taken for, weight 1, whatever the pixel filter: with a box or
// a gaussian by importance sampling that is the beauty's own filter; a splatted gaussian spreads the beauty
// over neighbours, which OIDN does not support anyway (it correlates the noise of neighbouring pixels).
layout(std430, binding = FEATURES_BINDING) buffer Features { vec4 features[]; };
#endif

uniform ivec4 region;     // the pixels rendered: x, y, width, height (the whole image, or the studio's render region)
uniform int tile_start;   // first pixel of this dispatch (row-major index within the region)
uniform int tile_pixels;
uniform uint sample_start;
uniform int sample_count;
uniform uint seed;
uniform float filter_stddev; // 0: box filter over the pixel; else a gaussian truncated at 4 stddev (Mitsuba's)
uniform float clamp_max;  // 0: off. Otherwise the most radiance one sample may add (a biased firefly filter)
uniform int splat_pixels; // 0: accumulate here; else write each sample to its slot (pixels in the image)

// Filter importance sampling (pbrt-v4, section 8.8): draw the offset from the pixel centre in proportion to
// the reconstruction filter and give every sample weight 1, so the filtered image is estimated unbiased.
float inverse_erf(float x) {  // Giles 2010, single precision
    float w = -log(max((1.0 - x) * (1.0 + x), 1e-30));
    float p;
    if (w < 5.0) {
        w -= 2.5;
        p = 2.81022636e-08;
        p = 3.43273939e-07 + p * w; p = -3.5233877e-06 + p * w; p = -4.39150654e-06 + p * w;
        p = 0.00021858087 + p * w; p = -0.00125372503 + p * w; p = -0.00417768164 + p * w;
        p = 0.246640727 + p * w; p = 1.50140941 + p * w;
    } else {
        w = sqrt(w) - 3.0;
        p = -0.000200214257;
        p = 0.000100950558 + p * w; p = 0.00134934322 + p * w; p = -0.00367342844 + p * w;
        p = 0.00573950773 + p * w; p = -0.0076224613 + p * w; p = 0.00943887047 + p * w;
        p = 1.00167406 + p * w; p = 2.83297682 + p * w;
    }
    return p * x;
}

vec2 pixel_offset(vec2 u) {
    if (filter_stddev <= 0.0 || splat_pixels > 0) return u - 0.5;  // uniform over the pixel
    // Each axis: a normal distribution truncated at +-4 stddev, by inverting its CDF.
    const float edge = 0.99993666;  // erf(4 / sqrt(2))
    vec2 x = (2.0 * u - 1.0) * edge;
    return filter_stddev * sqrt(2.0) * vec2(inverse_erf(x.x), inverse_erf(x.y));
}

// Where in its pixel a splatted sample was taken, in one float for splat.comp: 12 bits of x as the integer
// part, y in the fraction (both to 1/4096 of a pixel; plain float values, safe from NaN and denormal flushing).
float encode_pixel_position(vec2 u) { return floor(u.x * 4096.0) + min(u.y, 0.99975586); }

void main() {
    int local = int(gl_GlobalInvocationID.x);
    if (local >= tile_pixels) return;
    int region_index = tile_start + local;
    uvec2 pixel = uvec2(region.xy + ivec2(region_index % region.z, region_index / region.z));
    int pixel_index = int(pixel.y) * image_size.x + int(pixel.x);

    vec4 sum = splat_pixels > 0 ? vec4(0.0) : accumulation[pixel_index];
#if HAS_FEATURE_BUFFERS
    vec4 albedo_sum = features[FEATURE_ROWS * pixel_index], normal_sum = features[FEATURE_ROWS * pixel_index + 1];
#endif
    for (int k = 0; k < sample_count; k++) {
        Sampler sampler = sampler_start(pixel, sample_start + uint(k), seed);
        vec4 u = sample4(sampler);  // pixel position and lens position, jointly stratified
        vec3 lens_weight;  // 0 where the lens barrel or the glass blocks the ray (cat's eye, vignetting)
        Ray ray = camera_ray(vec2(pixel) + 0.5 + pixel_offset(u.xy), u.zw, lens_weight);
        bool through = max_component(lens_weight) > 0.0;
        vec3 l = through ? lens_weight * path_radiance(ray, sampler) : vec3(0.0);
#if HAS_FEATURE_BUFFERS
        if (through) {  // a ray the barrel blocks shows no surface: it is not counted
            albedo_sum += vec4(feature_albedo, 1.0);
            normal_sum.xyz += feature_normal;
        }
#endif
        // A NaN or infinity (a degenerate triangle, say) would poison the pixel forever: count it as black.
        if (any(isnan(l)) || any(isinf(l))) l = vec3(0.0);
        if (clamp_max > 0.0 && max_component(l) > clamp_max) l *= clamp_max / max_component(l);
        if (splat_pixels > 0) {
            accumulation[k * splat_pixels + pixel_index] = vec4(l, encode_pixel_position(u.xy));
        } else {
            sum += vec4(l, 1.0);
        }
    }
    if (splat_pixels == 0) accumulation[pixel_index] = sum;
#if HAS_FEATURE_BUFFERS
    features[FEATURE_ROWS * pixel_index] = albedo_sum;
    features[FEATURE_ROWS * pixel_index + 1] = normal_sum;
#endif
}
