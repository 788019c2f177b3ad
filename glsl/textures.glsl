// Texture lookups by surface (u, v). Records (TEXTURE_ROWS vec4 each, from render/textures.py) follow the
// materials in the Materials buffer, starting at row texture_base: (type, first texel, width, height),
// (tiles u, tiles v, texel format, -), colour a, colour b. The type is TEXTURE_IMAGE or TEXTURE_CHECKER.
// Image texels are linear RGB in image_data, as half floats (TEXELS_HALF: two uints a texel: (r, g), (b, -))
// or, for values beyond the half range, as 32-bit floats (TEXELS_FLOAT: three uints a texel).

layout(std430, binding = IMAGE_DATA_BINDING) readonly buffer ImageData { uint image_data[]; };

uniform int texture_base;

vec3 texel(int first, int width, int height, bool full_float, int x, int y) {
    x = ((x % width) + width) % width;  // repeat
    y = ((y % height) + height) % height;
    int n = y * width + x;
    if (full_float) {
        int i = first + 3 * n;
        return uintBitsToFloat(uvec3(image_data[i], image_data[i + 1], image_data[i + 2]));
    }
    int i = first + 2 * n;
    return vec3(unpackHalf2x16(image_data[i]), unpackHalf2x16(image_data[i + 1]).x);
}

vec3 texture_rgb(int t, vec2 uv) {
    vec4 r0 = materials[texture_base + TEXTURE_ROWS * t];
    vec4 r1 = materials[texture_base + TEXTURE_ROWS * t + 1];
    vec2 st = uv * r1.xy;  // tiles
    if (int(r0.x) == TEXTURE_CHECKER) {
        bool odd = (int(floor(st.x)) + int(floor(st.y))) % 2 != 0;
        return materials[texture_base + TEXTURE_ROWS * t + (odd ? 3 : 2)].xyz;
    }
    // Bilinear filtering between the four nearest texel centres; image row 0 is the top (v = 1).
    int first = floatBitsToInt(r0.y), width = int(r0.z), height = int(r0.w);
    bool full = int(r1.z) == TEXELS_FLOAT;
    vec2 p = vec2(st.x * float(width), (1.0 - st.y) * float(height)) - 0.5;
    vec2 f = fract(p);
    ivec2 i = ivec2(floor(p));
    vec3 a = mix(texel(first, width, height, full, i.x, i.y), texel(first, width, height, full, i.x + 1, i.y), f.x);
    vec3 b = mix(texel(first, width, height, full, i.x, i.y + 1),
                 texel(first, width, height, full, i.x + 1, i.y + 1), f.x);
    return mix(a, b, f.y);
}
