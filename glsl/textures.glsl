// Texture lookups by surface (u, v). Records (TEXTURE_ROWS vec4 each, from render/textures.py) follow the
// materials in the Materials buffer, starting at row texture_base:
//   row 0: (type, first texel, width, height); the type is TEXTURE_IMAGE or TEXTURE_CHECKER
//   rows 1, 2: the uv transform: s = dot(row 1, (u, v, 1)), t = dot(row 2, (u, v, 1)) (scene/textures.py)
//   images: row 3 (texel format, wrap mode, filter, -); checkerboards: rows 3, 4 colour a, colour b.
// Image texels are linear RGB in image_data, as half floats (TEXELS_HALF: two uints a texel: (r, g), (b, -))
// or, for values beyond the half range, as 32-bit floats (TEXELS_FLOAT: three uints a texel).
// An image spans (s, t) in [0, 1]^2 with its top row at t = 1; texel centres lie at half-integers of
// (s W, (1 - t) H), and the wrap modes and filters are Dr.Jit's (Mitsuba 3's bitmap), docs/scene-format.md.

layout(std430, binding = IMAGE_DATA_BINDING) readonly buffer ImageData { uint image_data[]; };

uniform int texture_base;

// i modulo n in [0, n): GLSL leaves % undefined for a negative operand, so shift i up by whole periods first.
int positive_mod(int i, int n) {
    if (i < 0) i += n * ((-i) / n + 1);
    return i % n;
}

// The texel column (or row) a lookup at integer position i of n reads, by the image's wrap mode.
int wrap_texel(int i, int n, int mode) {
    if (mode == TEXTURE_WRAP_CLAMP) return clamp(i, 0, n - 1);
    if (mode == TEXTURE_WRAP_MIRROR) {
        int m = positive_mod(i, 2 * n);  // the image, then its mirror image, repeated
        return m < n ? m : 2 * n - 1 - m;
    }
    return positive_mod(i, n);
}

struct ImageRecord {
    int first, width, height, wrap;
    bool full_float;
};

// The texel at column x, row y, both already wrapped into the image.
vec3 texel(ImageRecord im, int x, int y) {
    int n = y * im.width + x;
    if (im.full_float) {
        int i = im.first + 3 * n;
        return uintBitsToFloat(uvec3(image_data[i], image_data[i + 1], image_data[i + 2]));
    }
    int i = im.first + 2 * n;
    return vec3(unpackHalf2x16(image_data[i]), unpackHalf2x16(image_data[i + 1]).x);
}

vec3 texture_rgb(int t, vec2 uv) {
    int base = texture_base + TEXTURE_ROWS * t;
    vec4 r0 = materials[base], r3 = materials[base + 3];
    vec3 uv1 = vec3(uv, 1.0);
    vec2 st = vec2(dot(materials[base + 1].xyz, uv1), dot(materials[base + 2].xyz, uv1));
    if (int(r0.x) == TEXTURE_CHECKER) {
        // The parity of the square's column + row; & 1 reads it right for negative squares too.
        bool odd = ((int(floor(st.x)) + int(floor(st.y))) & 1) != 0;
        return odd ? materials[base + 4].xyz : r3.xyz;
    }
    ImageRecord im = ImageRecord(floatBitsToInt(r0.y), int(r0.z), int(r0.w), int(r3.y), int(r3.x) == TEXELS_FLOAT);
    vec2 p = vec2(st.x * float(im.width), (1.0 - st.y) * float(im.height));  // in texels, row 0 at the top
    if (int(r3.z) == TEXTURE_FILTER_NEAREST) {
        ivec2 i = ivec2(floor(p));
        return texel(im, wrap_texel(i.x, im.width, im.wrap), wrap_texel(i.y, im.height, im.wrap));
    }
    // Bilinear filtering between the four nearest texel centres: two columns and two rows, each wrapped once
    // (every lookup of an environment map comes here: wrapping per texel cost a glass scene 7% of its speed).
    p -= 0.5;
    vec2 f = fract(p);
    ivec2 i = ivec2(floor(p));
    int x0 = wrap_texel(i.x, im.width, im.wrap), x1 = wrap_texel(i.x + 1, im.width, im.wrap);
    int y0 = wrap_texel(i.y, im.height, im.wrap), y1 = wrap_texel(i.y + 1, im.height, im.wrap);
    vec3 a = mix(texel(im, x0, y0), texel(im, x1, y0), f.x);
    vec3 b = mix(texel(im, x0, y1), texel(im, x1, y1), f.x);
    return mix(a, b, f.y);
}
