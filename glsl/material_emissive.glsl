// Emissive (scene/materials/emissive.py): a light. It scatters only through the surface it holds (row 2, x),
// which resolve_material (glsl/bsdf.glsl) walks down to; on its own it reflects nothing.
// Included by glsl/bsdf.glsl through the generated dispatch (scene/materials/registry.py).

// Radiance a surface emits towards wo.
vec3 emitted_radiance(int m, bool front_face) {
    vec4 e = material_row(m, 1);
    return (front_face || e.w > 0.5) ? e.xyz : vec3(0.0);
}
