// Which parts of the kernel a scene needs. render/features.py passes each as a #define (0 or 1, or a bit
// mask of material types) so that a Cornell box is not slowed by code for textures, spheres or an
// environment map it does not have: on a SIMD device every lane pays for both sides of a branch that any
// lane takes (Mesa 22's llvmpipe pays for both sides of every branch, taken or not), and every loop runs
// its body at least once on llvmpipe. A kernel compiled without these defines is the general kernel, with
// everything in; the tests compare the two.
// 0: rays walk the kd-tree. N > 0: the scene has N primitives, few enough that testing them all is faster.
#ifndef FLAT_PRIMITIVES
#define FLAT_PRIMITIVES 0
#endif
#ifndef HAS_INSTANCES
#define HAS_INSTANCES 1
#endif
#ifndef HAS_SPHERES
#define HAS_SPHERES 1
#endif
#ifndef HAS_TEXTURES
#define HAS_TEXTURES 1
#endif
#ifndef HAS_ENVIRONMENT_LIGHT
#define HAS_ENVIRONMENT_LIGHT 1
#endif
#ifndef HAS_ENVIRONMENT_MAP
#define HAS_ENVIRONMENT_MAP 1
#endif
#ifndef HAS_AREA_LIGHTS
#define HAS_AREA_LIGHTS 1
#endif
#ifndef HAS_POINT_LIGHTS
#define HAS_POINT_LIGHTS 1
#endif
#ifndef HAS_SPOT_LIGHTS
#define HAS_SPOT_LIGHTS 1
#endif
#ifndef HAS_SUN
#define HAS_SUN 1
#endif
#ifndef HAS_LIGHTS_AT_POINT
#define HAS_LIGHTS_AT_POINT 1
#endif
#ifndef HAS_LIGHTS_BY_POWER
#define HAS_LIGHTS_BY_POWER 1
#endif
#ifndef HAS_NESTED_MATERIALS
#define HAS_NESTED_MATERIALS 1
#endif
#ifndef HAS_BECKMANN
#define HAS_BECKMANN 1
#endif
// Not a scene feature but an output: the denoiser's albedo and normal buffers (feature_buffers.glsl), off
// unless the host asks (render/tracer.py's feature_buffers), so a render without them pays nothing.
#ifndef HAS_FEATURE_BUFFERS
#define HAS_FEATURE_BUFFERS 0
#endif
#ifndef MATERIAL_TYPES
#define MATERIAL_TYPES 0xFFFF
#endif

// Whether material type `code` (one of render/gpu_layout.py's MATERIAL_* codes) can occur: a constant, so
// the compiler drops the code of every type the scene does not use.
#define HAS_MATERIAL(code) (((MATERIAL_TYPES) >> (code) & 1) != 0)
