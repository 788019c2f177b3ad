// Mask (scene/materials/mask.py): a cut-out. The cut is made during traversal (glsl/mask.glsl, included by
// the trace kernel before bsp.glsl); at a hit that stays, resolve_material (glsl/bsdf.glsl) walks on to the
// material it holds. Nothing else to shade here. Included by glsl/bsdf.glsl through the generated dispatch
// (scene/materials/registry.py).
