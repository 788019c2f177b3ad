#version 430
// The picture on the screen, made where the image already is: from the film's running sums to 8-bit sRGB
// pixels, so the studio reads back a quarter of the bytes and does no per-pixel work on the CPU.
//
// The same steps, in the same order, as lenslab.render.film (resolve, tone_map, to_8bit): radiance = sum /
// weight, times 2^exposure, through the chosen tone curve, sRGB-encoded, rounded to 8 bits. A pixel with no
// sample yet gets alpha 0, so the caller can show something else there (the studio's preview).

layout(local_size_x = LOCAL_SIZE_X) in;

layout(std430, binding = ACCUMULATION_BINDING) readonly buffer Accumulation { vec4 accumulation[]; };
layout(std430, binding = DISPLAY_BINDING) writeonly buffer Display { uint display[]; };  // RGBA8, R lowest

uniform ivec2 image_size;
uniform float exposure_scale;  // 2^stops
uniform int tone_map;          // TONE_MAP_CLAMP, TONE_MAP_REINHARD or TONE_MAP_FILMIC

// The curves' numbers are #defines from the Python that owns them (render/gpu_layout.py): FILMIC_* from
// lenslab.render.film, SRGB_* from lenslab.color. None is typed here.

vec3 filmic(vec3 x) {  // Narkowicz's fit of the ACES reference rendering transform (film._filmic)
    return clamp((x * (FILMIC_A * x + FILMIC_B)) / (x * (FILMIC_C * x + FILMIC_D) + FILMIC_E), 0.0, 1.0);
}

vec3 linear_to_srgb(vec3 x) {  // IEC 61966-2-1, as lenslab.color
    x = clamp(x, 0.0, 1.0);
    return mix(SRGB_SCALE * pow(x, vec3(1.0 / SRGB_EXPONENT)) - SRGB_OFFSET, SRGB_LINEAR_SLOPE * x,
               lessThanEqual(x, vec3(SRGB_LINEAR_CUTOFF)));
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= image_size.x || pixel.y >= image_size.y) return;
    int index = pixel.y * image_size.x + pixel.x;
    vec4 film = accumulation[index];
    if (!(film.a > 0.0)) {
        display[index] = 0u;
        return;
    }
    vec3 x = max(film.rgb / film.a, 0.0) * exposure_scale;
    if (tone_map == TONE_MAP_REINHARD) x = x / (1.0 + x);
    else if (tone_map == TONE_MAP_FILMIC) x = filmic(x);
    uvec3 level = uvec3(clamp(floor(linear_to_srgb(x) * 255.0 + 0.5), 0.0, 255.0));
    display[index] = level.r | (level.g << 8) | (level.b << 16) | (255u << 24);
}
