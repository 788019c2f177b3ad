#version 430
// The picture on the screen, made where the image already is: from the film's running sums to 8-bit display
// pixels, so the studio reads back a quarter of the bytes and does no per-pixel work on the CPU.
//
// The same steps, in the same order, as lenslab.render.film.display_pixels: radiance = sum / weight (never
// negative), through OpenColorIO's view transform (exposure and contrast, looks, the display's view and
// encoding), rounded to 8 bits. The transform is OCIO's own GLSL, generated for the chosen display, view and looks
// (lenslab.colour_management.view) and included here as "ocio_display.glsl"; its lookup tables are textures and
// its exposure and contrast uniforms, both set by render/tracer.py. A pixel with no sample yet gets alpha 0, so
// the caller can show something else there (the studio's preview).

layout(local_size_x = LOCAL_SIZE_X) in;

layout(std430, binding = ACCUMULATION_BINDING) readonly buffer Accumulation { vec4 accumulation[]; };
layout(std430, binding = DISPLAY_BINDING) writeonly buffer Display { uint display[]; };  // RGBA8, R lowest

uniform ivec2 image_size;

#include "ocio_display.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= image_size.x || pixel.y >= image_size.y) return;
    int index = pixel.y * image_size.x + pixel.x;
    vec4 film = accumulation[index];
    if (!(film.a > 0.0)) {
        display[index] = 0u;
        return;
    }
    vec3 shown = ocio_display(vec4(max(film.rgb / film.a, 0.0), 1.0)).rgb;
    // What OCIO leaves outside the display's range (an un-tone-mapped highlight, NaN of a broken look) clips.
    uvec3 level = uvec3(clamp(floor(shown * 255.0 + 0.5), 0.0, 255.0));
    display[index] = level.r | (level.g << 8) | (level.b << 16) | (255u << 24);
}
