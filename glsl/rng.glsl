// Random numbers for Monte Carlo integration.
//
// The default is a 4-D Sobol sequence with Owen scrambling and shuffling (Burley 2020, "Practical Hash-based
// Owen Scrambling"): stratified in (pixel x, pixel y, lens u, lens v), which is where thin-lens noise falls
// fastest. Further dimensions are "padded" with independently shuffled and scrambled 4-D draws, one set per
// bounce. SAMPLER_INDEPENDENT swaps in plain hashed random numbers for comparison.
//
// SOBOL_DIRECTIONS (4 x 32 direction numbers, Joe & Kuo) is defined by the host; see render/sobol.py.

const uint sobol_directions[128] = SOBOL_DIRECTIONS;

uint hash_combine(uint seed, uint v) { return seed ^ (v + (seed << 6) + (seed >> 2)); }

float u32_to_unit_float(uint x) { return min(float(x >> 8) * (1.0 / 16777216.0), 0.99999994); }

// All four dimensions of point `index` at once: dimension 1 is the bit-reversed index (van der Corput);
// the others XOR together the direction numbers of the index's set bits, in one pass over the bits.
uvec4 sobol4_u32(uint index) {
    uvec3 x = uvec3(0u);
    for (int bit = 0; bit < 32; bit++) {  // a fixed count: unrolled, every table read at a constant place
        uvec3 take = uvec3(0u - ((index >> uint(bit)) & 1u));
        x ^= take & uvec3(sobol_directions[32 + bit], sobol_directions[64 + bit], sobol_directions[96 + bit]);
    }
    return uvec4(bitfieldReverse(index), x);
}

uint laine_karras_permutation(uint x, uint seed) {
    x += seed;
    x ^= x * 0x6c50b47cU;
    x ^= x * 0xb82f1e52U;
    x ^= x * 0xc7afe638U;
    x ^= x * 0x8d22f6e6U;
    return x;
}

uint nested_uniform_scramble(uint x, uint seed) {
    return bitfieldReverse(laine_karras_permutation(bitfieldReverse(x), seed));
}

// The sampler state of one path: which pixel (seed), which sample, which 4-D set comes next.
struct Sampler {
    uint seed;
    uint index;
    uint set;
};

Sampler sampler_start(uvec2 pixel, uint sample_index, uint user_seed) {
    uint seed = hash_u32(hash_combine(hash_u32(user_seed + 0x9e3779b9U), pixel.x * 65537u + pixel.y * 7919u + 17u));
    return Sampler(seed, sample_index, 0u);
}

vec4 sample4(inout Sampler s) {
    uint seed = hash_u32(hash_combine(s.seed, s.set++));
#ifdef SAMPLER_INDEPENDENT
    uint base = hash_u32(hash_combine(seed, s.index));
    return vec4(u32_to_unit_float(hash_u32(base)), u32_to_unit_float(hash_u32(base + 1u)),
                u32_to_unit_float(hash_u32(base + 2u)), u32_to_unit_float(hash_u32(base + 3u)));
#else
    uvec4 x = sobol4_u32(nested_uniform_scramble(s.index, seed));
    vec4 u;
    for (uint dim = 0u; dim < 4u; dim++) {
        u[dim] = u32_to_unit_float(nested_uniform_scramble(x[dim], hash_combine(seed, dim)));
    }
    return u;
#endif
}
