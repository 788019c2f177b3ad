// Shared declarations: constants, the scene's storage buffers and the uniforms every kernel reads.
// The buffers are packed by app/lenslab/render/buffers.py. Their record sizes, type codes and binding points
// (MATERIAL_ROWS, GEOMETRY_ROWS, LIGHT_AREA, KD_NODES_BINDING ...) are not typed here: the host passes
// each as a #define from app/lenslab/render/gpu_layout.py to every shader it compiles.

#include "features.glsl"

const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;
const float INFINITY = 1.0 / 0.0;
const int NO_HIT = -1;
const float ONE_MINUS_EPSILON = 0.99999994;  // the largest float below 1

// kd-tree nodes (see bsp.py): interior x = split (float bits), y = (above child << 2) | axis;
// leaf x = first reference, y = (count << 2) | KD_LEAF. The below child of node i is node i + 1.
layout(std430, binding = KD_NODES_BINDING) readonly buffer KdNodes { uvec2 kd_nodes[]; };
layout(std430, binding = PRIM_REFS_BINDING) readonly buffer PrimRefs { int prim_refs[]; };
// GEOMETRY_ROWS (three) vec4 per primitive. Triangle: (v0, -), (e1, material), (e2, light).
// Sphere: (centre, radius), (-, material), (-, light). Material and light (the primitive's row in the light
// table, -1 if it emits nothing) are ints stored as float bits.
layout(std430, binding = GEOMETRY_BINDING) readonly buffer Geometry { vec4 geometry[]; };
// SHADING_ROWS (four) vec4 per triangle (spheres have none): (n0, u0), (n1, v0), (n2, u1), (v1, u2, v2, -).
layout(std430, binding = SHADING_BINDING) readonly buffer Shading { vec4 shading[]; };
// MATERIAL_ROWS vec4 per material (see bsdf.glsl), then TEXTURE_ROWS per texture from row texture_base
// (textures.glsl).
layout(std430, binding = MATERIALS_BINDING) readonly buffer Materials { vec4 materials[]; };
// LIGHT_ROWS vec4 per light (see lights.glsl).
layout(std430, binding = LIGHTS_BINDING) readonly buffer Lights { vec4 lights[]; };

// Mesh groups placed by instances (render/instancing.py): INSTANCE_ROWS vec4 per instance. Rows 0-2: world to
// group space (a 3x4 matrix, one row each); 3: the group's box min, its tree's root node (int bits); 4: box max,
// the instance's material (int bits); 5-7: group space to world. The transpose of rows 0-2's 3x3 part takes
// normals back to the world (the inverse-transpose of 5-7's).
layout(std430, binding = INSTANCES_BINDING) readonly buffer Instances { vec4 instances[]; };

uniform int triangle_count;   // every triangle in the geometry buffer: the groups' (first), then the world's
uniform vec3 scene_min;       // the box of the world's own primitives' tree
uniform vec3 scene_max;
uniform int world_root;       // the row of that tree's root in kd_nodes (after the groups' trees)
uniform int first_world_prim; // the world's own primitives' first row in geometry (after the groups' triangles)
uniform int instance_count;
uniform int instance_root;    // the instances' own tree's root in kd_nodes (after the world's), or -1: none
uniform vec3 instances_min;   // that tree's box
uniform vec3 instances_max;

uniform int light_count;      // entries in the light table
uniform vec3 env_radiance;    // constant environment

struct Ray {
    vec3 o;
    vec3 d;
};

const int NO_INSTANCE = -1;

struct Hit {
    float t;
    int prim;
    vec2 uv;  // barycentrics (b1, b2) on triangles
    int instance;  // the instance whose group holds prim, or NO_INSTANCE for the world's own primitives
};

int material_of(int prim) { return floatBitsToInt(geometry[GEOMETRY_ROWS * prim + 1].w); }
int light_of(int prim) { return floatBitsToInt(geometry[GEOMETRY_ROWS * prim + 2].w); }
bool is_sphere(int prim) { return HAS_SPHERES != 0 && prim >= triangle_count; }

uint hash_u32(uint x) {  // lowbias32 (Chris Wellons): rng.glsl's scrambles, and choices made by hashing a hit
    x ^= x >> 16; x *= 0x7feb352dU; x ^= x >> 15; x *= 0x846ca68bU; x ^= x >> 16;
    return x;
}

// A number in [0, 1) hashed from the bits of a point or direction a, two more words b and a last word x: the
// choices made by hashing a hit or a ray (a blend's pick, a mask's cut-out), which take no sampler dimension.
float hash_unit(vec3 a, vec2 b, uint x) {
    uvec3 ua = floatBitsToUint(a);
    uvec2 ub = floatBitsToUint(b);
    uint h = hash_u32(ua.x ^ hash_u32(ua.y ^ hash_u32(ua.z ^ hash_u32(ub.x ^ hash_u32(ub.y ^ hash_u32(x))))));
    return float(h >> 8) * (1.0 / 16777216.0);
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
float max_component(vec3 c) { return max(c.x, max(c.y, c.z)); }
