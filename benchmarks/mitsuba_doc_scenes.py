"""Mitsuba 3's own documentation and example scenes, through ``lenslab validate --files`` and its goal.

The scenes are Mitsuba's, not ours, and large: they are exported from a clone of Mitsuba's data repository into
a folder outside this checkout, then validated there. Which scenes, from which commit, and why the others are
left out: the lists below, and docs/validation.md ("Mitsuba's own scenes"), which holds the last run's table.

    git clone https://github.com/mitsuba-renderer/mitsuba-data  (or any copy of it: a bare one will do)
    python benchmarks/mitsuba_doc_scenes.py export --git-dir mitsuba-data/.git --dest /tmp/mitsuba_scenes
    python benchmarks/mitsuba_doc_scenes.py run --dest /tmp/mitsuba_scenes -- --resolution 96 --spp 128 \\
        --reference-spp 1024 --markdown /tmp/mitsuba_scenes.md

``run`` passes what follows ``--`` to ``lenslab validate --files``; ``--list`` prints the selected files.
Mitsuba's images are cached (``--cache-dir``, ~/.cache/lenslab/validate by default), so a rerun after a
LensLab change costs LensLab's renders only.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

SOURCE_REPO = "mitsuba-renderer/mitsuba-data"  # the submodule resources/data of mitsuba-renderer/mitsuba3
SOURCE_COMMIT = "01100fa9b0b154492061a92404f26dcd7b784dbb"  # 2026-06-20, "Updated refs for hetero_spectral..."
EXPORTED = ("docs/scenes", "scenes", "common")  # the scenes, what they include, their meshes and textures

# Scenes that use surface features only: the documentation's plugin gallery (docs/scenes) and the examples.
SELECTED = (
    "docs/scenes/bsdf_blendbsdf.xml",
    "docs/scenes/bsdf_bumpmap_with.xml",
    "docs/scenes/bsdf_bumpmap_without.xml",
    "docs/scenes/bsdf_conductor_aluminium.xml",
    "docs/scenes/bsdf_conductor_gold.xml",
    "docs/scenes/bsdf_dielectric_diamond.xml",
    "docs/scenes/bsdf_dielectric_glass.xml",
    "docs/scenes/bsdf_diffuse_plain.xml",
    "docs/scenes/bsdf_diffuse_textured.xml",
    "docs/scenes/bsdf_mask_after.xml",
    "docs/scenes/bsdf_mask_before.xml",
    "docs/scenes/bsdf_normalmap_with.xml",
    "docs/scenes/bsdf_normalmap_without.xml",
    "docs/scenes/bsdf_plastic_default.xml",
    "docs/scenes/bsdf_plastic_diffuse.xml",
    "docs/scenes/bsdf_plastic_nopreserve.xml",
    "docs/scenes/bsdf_plastic_preserve.xml",
    "docs/scenes/bsdf_plastic_shiny.xml",
    "docs/scenes/bsdf_roughconductor_anisotropic_aluminium.xml",
    "docs/scenes/bsdf_roughconductor_copper.xml",
    "docs/scenes/bsdf_roughconductor_textured_carbon.xml",
    "docs/scenes/bsdf_roughdielectric_glass.xml",
    "docs/scenes/bsdf_roughdielectric_rough.xml",
    "docs/scenes/bsdf_roughdielectric_textured.xml",
    "docs/scenes/bsdf_roughplastic_beckmann.xml",
    "docs/scenes/bsdf_roughplastic_diffuse.xml",
    "docs/scenes/bsdf_roughplastic_ggx.xml",
    "docs/scenes/bsdf_roughplastic_nopreserve.xml",
    "docs/scenes/bsdf_roughplastic_preserve.xml",
    "docs/scenes/bsdf_thindielectric_glass.xml",
    "docs/scenes/bsdf_twosided_cbox.xml",
    "docs/scenes/bsdf_twosided_cbox_onesided.xml",
    "docs/scenes/emitter_projector_constant.xml",
    "docs/scenes/emitter_projector_textured.xml",
    "docs/scenes/emitter_spot_no_texture.xml",
    "docs/scenes/emitter_spot_texture.xml",
    "docs/scenes/integrator_aov.xml",
    "docs/scenes/integrator_depth_1.xml",
    "docs/scenes/integrator_depth_2.xml",
    "docs/scenes/integrator_depth_3.xml",
    "docs/scenes/integrator_depth_inf.xml",
    "docs/scenes/integrator_direct_both.xml",
    "docs/scenes/integrator_direct_bsdf.xml",
    "docs/scenes/integrator_direct_lum.xml",
    "docs/scenes/sampler_independent_16spp.xml",
    "docs/scenes/sampler_independent_25spp.xml",
    "docs/scenes/sampler_ldsampler_16spp.xml",
    "docs/scenes/sampler_multijitter_16spp.xml",
    "docs/scenes/sampler_orthogonal_25spp.xml",
    "docs/scenes/sampler_stratified_16spp.xml",
    "docs/scenes/sensor_perspective.xml",
    "docs/scenes/sensor_perspective_large_fov.xml",
    "docs/scenes/sensor_thinlens.xml",
    "docs/scenes/sensor_thinlens_small_aperture.xml",
    "docs/scenes/shape_cylinder_onesided.xml",
    "docs/scenes/shape_cylinder_twosided.xml",
    "docs/scenes/shape_disk.xml",
    "docs/scenes/shape_disk_parameterization.xml",
    "docs/scenes/shape_ply_bunny.xml",
    "docs/scenes/shape_ply_bunny_facet.xml",
    "docs/scenes/shape_rectangle.xml",
    "docs/scenes/shape_rectangle_parameterization.xml",
    "docs/scenes/shape_sdfgrid.xml",
    "docs/scenes/shape_sdfgrid_analytic.xml",
    "docs/scenes/shape_sphere_basic.xml",
    "docs/scenes/shape_sphere_light_analytic.xml",
    "docs/scenes/shape_sphere_light_mesh.xml",
    "docs/scenes/shape_sphere_parameterization.xml",
    "docs/scenes/texture_checkerboard.xml",
    "docs/scenes/texture_mesh_attribute_face.xml",
    "docs/scenes/texture_mesh_attribute_vertex.xml",
    "docs/scenes/variants_cbox_rgb.xml",
    "scenes/cbox/cbox.xml",
    "scenes/cbox/cbox-rgb.xml",
    "scenes/hello.xml",
    "scenes/matpreview/matpreview.xml",
)

_POLARISED = "polarisation: rendered by Mitsuba's documentation in a polarised variant"
_TEMPLATE = "a template of principled_blend_scene_creation.py that Mitsuba 3.9 cannot open as it is"
EXCLUDED = {
    "docs/scenes/bsdf_hair_blonde.xml": "hair BSDF and curves",
    "docs/scenes/bsdf_hair_brown.xml": "hair BSDF and curves",
    "docs/scenes/shape_bsplinecurve_basic.xml": "curves (Mitsuba's hair primitive)",
    "docs/scenes/shape_bsplinecurve_parameterization.xml": "curves (Mitsuba's hair primitive)",
    "docs/scenes/shape_linearcurve_basic.xml": "curves (Mitsuba's hair primitive)",
    "docs/scenes/shape_linearcurve_parameterization.xml": "curves (Mitsuba's hair primitive)",
    "docs/scenes/medium_homogeneous_sss.xml": "a participating medium",
    "docs/scenes/medium_homogeneous_sss_textured.xml": "a participating medium",
    "docs/scenes/bsdf_polarizer_absorbing.xml": _POLARISED,
    "docs/scenes/bsdf_polarizer_aligned.xml": _POLARISED,
    "docs/scenes/bsdf_polarizer_middle.xml": _POLARISED,
    "docs/scenes/bsdf_pplastic.xml": _POLARISED,
    "docs/scenes/bsdf_pplastic_diffuse.xml": _POLARISED,
    "docs/scenes/bsdf_pplastic_diffuse_stokes.xml": _POLARISED + " (Stokes output)",
    "docs/scenes/bsdf_pplastic_specular.xml": _POLARISED,
    "docs/scenes/bsdf_pplastic_specular_stokes.xml": _POLARISED + " (Stokes output)",
    "docs/scenes/integrator_stokes_cbox.xml": _POLARISED + " (Stokes output)",
    "docs/scenes/bsdf_measured_polarized_gold.xml": _POLARISED + "; its measured data is not in the repository",
    "docs/scenes/bsdf_measured_polarized_gold_stokes.xml": _POLARISED + "; its measured data is not in the repository",
    "docs/scenes/bsdf_measured_polarized_fakegold.xml": _POLARISED + "; its measured data is not in the repository",
    "docs/scenes/bsdf_measured_polarized_fakegold_stokes.xml": _POLARISED + "; its measured data is not in the "
                                                                        "repository",
    "docs/scenes/variants_cbox_spectral.xml": "spectral: the same file as variants_cbox_rgb, shown rendered in a "
                                              "spectral variant",
    "scenes/cbox/cbox-spectral.xml": "spectral: measured reflectance and emission spectra",
    "docs/scenes/shape_instance_fractal.xml": "not in the snapshot (a large generated file, made by "
                                              "generate_instance_fractal.py)",
    "docs/scenes/principled_blend_creation/scene_studio.xml": "its environment map, studio.exr, is not in the snapshot",
    "docs/scenes/principled_blend_creation/scene.xml": _TEMPLATE + ' (shape "Sphere")',
    "docs/scenes/principled_blend_creation/scene_light.xml": _TEMPLATE + " (studio.exr, not in the snapshot)",
    "docs/scenes/principled_blend_creation/scene_thin.xml": _TEMPLATE + ' (shape "Rectangle")',
    "docs/scenes/principled_blend_creation/scene_thin_light.xml": _TEMPLATE + ' (shape "Rectangle")',
    "docs/scenes/sensor_orthographic.xml": "broken at this commit: it has no <path> to ../../common as the others do, "
                                           "so neither Mitsuba nor LensLab finds its mesh and environment map",
    "docs/scenes/sensor_orthographic_2.xml": "broken at this commit: names meshes/cbox/cbox_*.obj, which the "
                                             "repository does not have (Mitsuba cannot open it either)",
    "docs/scenes/include/*.xml": "fragments the scenes above include, not scenes",
    "scenes/cbox/fragments/*.xml": "fragments the cbox scenes include, not scenes",
}


def export(git_dir: Path, dest: Path, commit: str) -> list[str]:
    """Copy EXPORTED at ``commit`` out of a (bare) git repository into ``dest``; the paths it could not read
    (large files stored elsewhere) are returned."""
    commit = subprocess.run(["git", "--git-dir", str(git_dir), "rev-parse", f"{commit}^{{commit}}"], check=True,
                            capture_output=True, text=True).stdout.strip()
    listing = subprocess.run(["git", "--git-dir", str(git_dir), "ls-tree", "-r", "--name-only", commit, *EXPORTED],
                             check=True, capture_output=True, text=True).stdout.split("\n")
    missing = []
    for name in filter(None, listing):
        blob = subprocess.run(["git", "--git-dir", str(git_dir), "cat-file", "blob", f"{commit}:{name}"],
                              capture_output=True)
        if blob.returncode != 0:
            missing.append(name)
            continue
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(blob.stdout)
    (dest / "SOURCE").write_text(f"{SOURCE_REPO} {commit}\n", encoding="utf-8")
    return missing


def main(argv: list[str]) -> int:
    argv, passed = (argv[: argv.index("--")], argv[argv.index("--") + 1:]) if "--" in argv else (argv, [])
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("command", choices=("export", "run"))
    p.add_argument("--dest", type=Path, default=Path("/tmp/mitsuba_scenes"), help="where the scenes are (/tmp/mitsuba_scenes)")
    p.add_argument("--git-dir", type=Path, help="export: the mitsuba-data repository's git directory")
    p.add_argument("--commit", default=SOURCE_COMMIT, help=f"export: which commit ({SOURCE_COMMIT[:10]})")
    p.add_argument("--only", default="", help="run: only the selected files whose path holds one of these (a,b)")
    p.add_argument("--list", action="store_true", help="run: print the files instead of validating them")
    args = p.parse_args(argv)
    if args.command == "export":
        if args.git_dir is None:
            p.error("export needs --git-dir")
        missing = export(args.git_dir, args.dest, args.commit)
        print(f"exported {', '.join(EXPORTED)} to {args.dest}" + (f"; not in the repository: {', '.join(missing)}"
                                                                   if missing else ""))
        return 0
    only = [w for w in args.only.split(",") if w]
    files = [args.dest / name for name in SELECTED if not only or any(w in name for w in only)]
    absent = [str(f) for f in files if not f.is_file()]
    if absent:
        print(f"not exported yet (run the export first): {', '.join(absent[:3])}" + (" ..." if len(absent) > 3 else ""),
              file=sys.stderr)
        return 2
    if args.list:
        print("\n".join(str(f) for f in files))
        return 0
    from lenslab.validate.cli import main as validate

    return validate(["--files", *map(str, files), *passed])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
