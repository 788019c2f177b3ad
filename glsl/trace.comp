#version 430
// Entry kernel of the progressive renderer: one invocation per pixel of a tile of consecutive pixels,
// adding `sample_count` samples (sample indices sample_start ...) to that pixel's running sum.
// The sum is loaded once and each sample added in index order, so the image is bit-identical however the
// host splits the work into dispatches.

layout(local_size_x = LOCAL_SIZE_X) in;

#include "common.glsl"
#include "rng.glsl"
#include "sampling.glsl"
#include "camera.glsl"
#include "intersect.glsl"
#include "bsp.glsl"
#include "surface.glsl"
#include "textures.glsl"
#include "microfacet.glsl"
#include "bsdf.glsl"
#include "lights.glsl"
#include "integrator.glsl"

// rgb: sum of radiance samples; a: number of samples.
layout(std430, binding = 6) buffer Accumulation { vec4 accumulation[]; };

uniform int tile_start;   // first pixel (row-major index) of this dispatch
uniform int tile_pixels;
uniform uint sample_start;
uniform int sample_count;
uniform uint seed;
uniform float clamp_max;  // 0: off. Otherwise the most radiance one sample may add (a biased firefly filter)

void main() {
    int local = int(gl_GlobalInvocationID.x);
    if (local >= tile_pixels) return;
    int pixel_index = tile_start + local;
    uvec2 pixel = uvec2(pixel_index % image_size.x, pixel_index / image_size.x);

    vec4 sum = accumulation[pixel_index];
    for (int k = 0; k < sample_count; k++) {
        Sampler sampler = sampler_start(pixel, sample_start + uint(k), seed);
        vec4 u = sample4(sampler);  // pixel jitter (box filter) and lens position, jointly stratified
        Ray ray = camera_ray(vec2(pixel) + u.xy, u.zw);
        vec3 l = path_radiance(ray, sampler);
        // A NaN or infinity (a degenerate triangle, say) would poison the pixel forever: count it as black.
        if (any(isnan(l)) || any(isinf(l))) l = vec3(0.0);
        if (clamp_max > 0.0 && max_component(l) > clamp_max) l *= clamp_max / max_component(l);
        sum += vec4(l, 1.0);
    }
    accumulation[pixel_index] = sum;
}
