"""``lenslab validate``: the metrics and the table always; the command itself only where Mitsuba 3 renders."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from lenslab.validate import metrics, mitsuba_env, report


# ---------------------------------------------------------------------------------------------------------
# Pure Python: always
# ---------------------------------------------------------------------------------------------------------
def test_block_means_and_bias_are_relative_per_16x16_block():
    ref = np.ones((32, 48, 3))
    image = ref.copy()
    image[:16, :16] *= 1.05  # one block 5% bright
    image[16:, 32:, 0] = 0.7  # one block's red channel 30% dark: its mean 10% dark
    assert metrics.block_means(ref).shape == (2, 3)
    bias = metrics.block_bias(image, ref)
    assert np.allclose(bias, [[0.05, 0, 0], [0, 0, -0.1]])
    summary = metrics.summarize_bias(bias)
    assert summary.max_abs == pytest.approx(0.1) and summary.median_abs == 0.0 and summary.blocks == 6
    assert not summary.meets() and metrics.BiasSummary(0.019, 0.009, 6).meets()


def test_dark_blocks_are_left_out_and_tiny_images_refused():
    ref = np.ones((16, 32, 3))
    ref[:, 16:] = 1e-4
    image = ref * 2
    bias = metrics.block_bias(image, ref)
    assert bias[0, 0] == pytest.approx(1.0) and np.isnan(bias[0, 1])
    assert metrics.summarize_bias(bias).blocks == 1
    assert metrics.summarize_bias(np.full((2, 2), np.nan)).blocks == 0
    with pytest.raises(ValueError, match="no 16 x 16 block"):
        metrics.block_means(np.ones((8, 8, 3)))


def test_relative_mse():
    ref = np.full((4, 4, 3), 2.0)
    assert metrics.relative_mse(ref, ref) == 0.0
    assert metrics.relative_mse(ref + 0.2, ref) == pytest.approx(0.04 / 4.01)
    rng = np.random.default_rng(0)
    noisy = ref + rng.normal(0, 0.1, ref.shape)
    noisier = ref + rng.normal(0, 0.3, ref.shape)
    assert metrics.relative_mse(noisy, ref) < metrics.relative_mse(noisier, ref)
    with pytest.raises(ValueError, match="differ in shape"):
        metrics.relative_mse(ref, ref[:2])


def test_table_formatting():
    text = report.format_table([("cornell_dof", "128x128", "0.50%"), ("bokeh", "64x64", "12.00%")],
                               header=("scene", "size", "bias"))
    lines = text.splitlines()
    assert lines[0].split() == ["scene", "size", "bias"] and set(lines[1]) <= {"-", " "}
    assert lines[2].startswith("cornell_dof  128x128") and lines[3].split() == ["bokeh", "64x64", "12.00%"]
    assert len({line.index(word) for line, word in zip(lines[2:], ("128x128", "64x64"))}) == 1  # aligned columns
    md = report.markdown_table([("a", "b")], header=("x", "y"))
    assert md.splitlines() == ["| x | y |", "| --- | --- |", "| a | b |"]
    assert report._pct(0.0123) == "1.23%" and report._pct(float("nan")) == "n/a"


def test_difference_image_colours():
    ref = np.ones((2, 2, 3))
    image = ref.copy()
    image[0, 0] = 2.0  # brighter: red
    image[1, 1] = 0.5  # darker: blue
    diff = report.difference_image(image, ref)
    assert tuple(diff[0, 0]) == (255, 0, 0) and tuple(diff[1, 1]) == (0, 0, 255) and tuple(diff[0, 1]) == (255, 255, 255)


def test_missing_mitsuba_is_one_line_and_status_1(monkeypatch, capsys, hide_package):
    monkeypatch.setattr(mitsuba_env, "_mitsuba", None)
    monkeypatch.delitem(sys.modules, "mitsuba", raising=False)
    hide_package("mitsuba")
    from lenslab.cli import main

    assert main(["validate", "--scenes", "bokeh"]) == 1
    err = capsys.readouterr().err
    assert err.strip().splitlines() == ["lenslab validate: Mitsuba 3 is not installed: pip install 'lenslab[validate]'"]


def test_llvm_path_is_set_only_when_unset_and_present(tmp_path):
    lib = tmp_path / "libLLVM.so.19.1"
    env: dict[str, str] = {}
    mitsuba_env.prepare_environment(env, lib)
    assert env == {}  # not installed: leave Dr.Jit to its own search
    lib.write_bytes(b"")
    mitsuba_env.prepare_environment(env, lib)
    assert env == {"DRJIT_LIBLLVM_PATH": str(lib)}
    env = {"DRJIT_LIBLLVM_PATH": "/elsewhere/libLLVM.so"}
    mitsuba_env.prepare_environment(env, lib)
    assert env["DRJIT_LIBLLVM_PATH"] == "/elsewhere/libLLVM.so"
    assert "apt-get install libllvm19" in mitsuba_env.NO_LLVM


def test_the_advice_when_mitsuba_cannot_render_fits_the_variant_chosen():
    on_cpu = mitsuba_env.unavailable_message("jit aborted", "llvm_ad_rgb")
    assert "jit aborted" in on_cpu and "apt-get install libllvm19" in on_cpu
    on_gpu = mitsuba_env.unavailable_message("cuda_init failed", "cuda_ad_rgb")
    assert "cuda_init failed" in on_gpu and "NVIDIA" in on_gpu and "LLVM" not in on_gpu


def test_usage_errors(capsys):
    from lenslab.validate.cli import main

    assert main(["--scenes", "nope"]) == 2
    assert "unknown scene 'nope'" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------------------
# With Mitsuba 3: the command itself, on tiny images
# ---------------------------------------------------------------------------------------------------------
# The `mitsuba` fixture (tests/conftest.py) gives Mitsuba's module, or skips saying why it cannot render here.


@pytest.mark.slow
@pytest.mark.gl
def test_validate_command_prints_the_table_and_writes_docs(mitsuba, tmp_path, capsys):
    from lenslab.validate.cli import main

    status = main(["--scenes", "point_sun,bokeh", "--spp", "2", "--reference-spp", "8", "--bias-spp", "2",
                   "--resolution", "32", "--write-docs", "--docs-dir", str(tmp_path)])
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0].split()[:2] == ["scene", "size"]
    assert lines[2].startswith("point_sun") and lines[3].startswith("bokeh") and "32x32" in lines[2]
    # At 2 spp a goal may well be missed; whatever the table says, the exit status says the same.
    verdicts = [lines[2].split()[-1], lines[3].split()[-1]]
    assert set(verdicts) <= {"met", "MISSED"}
    assert status == (0 if verdicts == ["met", "met"] else 1)
    doc = (tmp_path / "validation.md").read_text()
    assert "| point_sun | 32x32 |" in doc and "Machine: CPU:" in doc
    for name in ("point_sun", "bokeh"):
        for kind in ("mitsuba", "lenslab", "difference"):
            assert (tmp_path / "validation" / f"{name}-{kind}.png").is_file()
            assert f"validation/{name}-{kind}.png" in doc


@pytest.mark.gl
def test_both_renderers_agree_on_a_point_lit_scene(mitsuba):
    from lenslab.render.tracer import Renderer
    from lenslab.validate.runner import validate_scene

    renderer = Renderer()
    try:
        result = validate_scene("point_sun", spp=16, reference_spp=64, bias_spp=16, res=32, renderer=renderer)
    finally:
        renderer.release()
    assert result.reference.image.shape == (32, 32, 3) and result.lenslab.image.shape == (32, 32, 3)
    assert result.lenslab_bias.blocks >= 3
    assert result.lenslab_bias.median_abs < 0.1  # the same picture (a wrong light direction is far off)


# ---------------------------------------------------------------------------------------------------------
# --files: any scene files against the --files goal (nothing dropped, image within 2%)
# ---------------------------------------------------------------------------------------------------------
SERIALIZED = ('/s/docs/scenes/include/matpreview.xml:9: <shape type="serialized" id="Plane">: Mitsuba .serialized '
              'meshes are not readable yet: shape skipped (convert it to PLY)')
CHECKER = ("/s/a.xml:41: <texture type=\"checkerboard\" id=\"planetex\">: textures are not supported yet: the "
           "checkerboard's mean colour (0.3, 0.3, 0.3) used")
FILTER = '/s/a.xml:12: <rfilter type="tent">: reconstruction filter "tent" is not supported: a box filter is used'
SAMPLER = ('/s/b.xml:4: <sampler type="independent" id="s">: a sampler belongs inside the <sensor> (Mitsuba 3 '
           'ignores it here too): ignored')


def test_warnings_are_sorted_into_drops_approximations_and_notes():
    from lenslab.validate import findings

    assert findings.kind_of(SERIALIZED) == findings.DROPS
    assert findings.kind_of(CHECKER) == findings.DROPS
    assert findings.kind_of(FILTER) == findings.APPROXIMATES
    assert findings.kind_of(SAMPLER) == findings.NOTES
    # one element's several notes are judged one by one; the feature drops the id and blanks the numbers
    both = ('/s/c.xml:3: <bsdf type="roughconductor" id="m">: anisotropic roughness (0.05, 0.3) is rendered '
            'isotropic (alpha 0.12); a textured alpha is not supported: 0.1 used')
    found = findings.findings([both])
    assert [f.kind for f in found] == [findings.APPROXIMATES, findings.DROPS]
    assert found[0].feature == '<bsdf type="roughconductor">: anisotropic roughness (#, #) is rendered isotropic (alpha #)'
    assert findings.findings([SERIALIZED])[0].feature == \
        '<shape type="serialized">: Mitsuba .serialized meshes are not readable yet'


def test_missing_features_ranked_by_failing_scenes():
    from lenslab.validate import findings

    other = SERIALIZED.replace('id="Plane"', 'id="Interior"').replace(":9:", ":65:")
    ranked = findings.rank_missing_features({"a": [SERIALIZED, other, CHECKER], "b": [SERIALIZED, FILTER],
                                             "c": [CHECKER, SAMPLER], "d": [SERIALIZED]})
    assert [(m.feature.split(":")[0], m.scenes, m.sole_blocker) for m in ranked] == [
        ('<shape type="serialized">', ("a", "b", "d"), ("b", "d")),  # a also needs textures
        ('<texture type="checkerboard">', ("a", "c"), ("c",)),
        ('<rfilter type="tent">', ("b",), ()),  # approximations never block on their own
    ]


def test_a_scene_lenslab_refuses_counts_its_reason_as_a_missing_feature():
    from lenslab.validate import findings

    refused = '/s/carbon.xml: line 4: <bsdf type="roughconductor" id="m">: unknown conductor material "a-C"'
    ranked = findings.rank_missing_features({"carbon": [CHECKER], "plain": [CHECKER]}, {"carbon": refused})
    assert [(m.feature, m.kind, m.scenes, m.sole_blocker) for m in ranked] == [
        ('<texture type="checkerboard">: textures are not supported yet', findings.DROPS, ("carbon", "plain"),
         ("plain",)),
        ('<bsdf type="roughconductor">: unknown conductor material "a-C"', findings.DROPS, ("carbon",), ()),
    ]


def test_total_light_and_the_95th_percentile():
    ref = np.ones((16, 32, 3))
    assert metrics.total_light(ref * 1.03, ref) == pytest.approx(0.03)
    assert np.isnan(metrics.total_light(ref, ref * 0))
    bias = np.linspace(0, 1, 101)
    assert metrics.summarize_bias(bias).p95_abs == pytest.approx(0.95)
    with pytest.raises(ValueError, match="differ in shape"):
        metrics.total_light(ref, ref[:8])


def test_file_verdicts_and_their_rows(tmp_path):
    from lenslab.validate.files import FileResult, display_names

    good = metrics.BiasSummary(0.05, 0.012, 20, 0.03)
    passed = FileResult("cbox", tmp_path / "cbox.xml", warnings=[SAMPLER], resolution=(96, 96), lenslab_bias=good,
                        mitsuba_bias=good, total_light=-0.015)
    assert passed.verdict == "PASS" and passed.reasons() == []
    dropped = FileResult("mat", tmp_path / "mat.xml", warnings=[SERIALIZED, FILTER], resolution=(96, 72),
                         lenslab_bias=metrics.BiasSummary(0.5, 0.031, 20, 0.4), mitsuba_bias=good, total_light=0.25)
    assert dropped.verdict == "FAIL"
    assert dropped.reasons() == ["drops content (1)", "median block 3.1%", "total light +25.0%"]
    broken = FileResult("broken", tmp_path / "broken.xml", error="Mitsuba: no such file")
    assert broken.verdict == "ERROR"
    rows = [report.files_row(r) for r in (passed, dropped, broken)]
    assert rows[0] == ("cbox", "96x96", "1", "0", "1.20%", "3.00%", "1.20%", "-1.50%", "PASS", "")
    assert rows[1][-2:] == ("FAIL", "drops content (1), median block 3.1%, total light +25.0%")
    assert rows[2] == ("broken", "-", "0", "0", "n/a", "n/a", "n/a", "n/a", "ERROR", "Mitsuba: no such file")
    text = report.format_files_report([passed, dropped, broken], spp=16, reference_spp=64)
    assert f"  drops: {SERIALIZED}" in text.splitlines() and f"  approximates: {FILTER}" in text.splitlines()
    assert "Missing features" in text
    md = report.markdown_files_report([passed, dropped, broken], spp=16, reference_spp=64)
    assert "| mat | 96x72 | 2 | 1 |" in md and "`<shape type=\"serialized\">: Mitsuba .serialized" in md
    assert display_names([tmp_path / "a" / "x.xml", tmp_path / "b" / "y.xml"]) == ["a/x", "b/y"]
    assert display_names([tmp_path / "a" / "x.xml"]) == ["x"]


def test_files_usage_errors(capsys):
    from lenslab.validate.cli import main

    assert main(["--files", "a.xml", "--scenes", "bokeh"]) == 2
    assert "--scenes is for the built-in scenes" in capsys.readouterr().err
    assert main(["-D", "x=1"]) == 2
    assert "-D goes with --files" in capsys.readouterr().err
    assert main(["--files", "a.xml", "-D", "x"]) == 2
    assert "expected NAME=VALUE" in capsys.readouterr().err


def test_write_docs_keeps_the_section_on_mitsubas_own_scenes(tmp_path):
    own = report.OWN_SCENES_HEADING + "\n\n| scene | goal |\n| a | PASS |\n"
    (tmp_path / "validation.md").write_text("# old\n\nold results\n\n" + own)
    report.write_docs([], tmp_path, spp=1, reference_spp=1, bias_spp=1)
    text = (tmp_path / "validation.md").read_text()
    assert text.startswith("# Validation against Mitsuba 3") and "old results" not in text and text.endswith(own)


TINY_SCENE = """<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="640"/><integer name="height" value="480"/>
            <rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.8"/></emitter>
    <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.4, 0.2"/></bsdf></shape>
</scene>
"""


@pytest.mark.gl
def test_validate_files_renders_a_tiny_scene_at_the_chosen_width(mitsuba, tmp_path, capsys):
    from lenslab.validate.cli import main

    scene = tmp_path / "tiny.xml"
    scene.write_text(TINY_SCENE)  # its $spp has no default: the validator sets it, as Mitsuba's docs script does
    status = main(["--files", str(scene), "--spp", "32", "--reference-spp", "128", "--resolution", "32",
                   "--cache-dir", str(tmp_path / "cache"), "--markdown", str(tmp_path / "report.md")])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:4] == ["scene", "size", "warnings", "drops"]
    cells = lines[2].split()
    assert cells[:4] == ["tiny", "32x24", "0", "0"]  # 640 x 480 scaled to 32 wide; nothing warned about
    assert cells[8] in ("PASS", "FAIL") and status == (0 if cells[8] == "PASS" else 1)
    assert float(cells[4].rstrip("%")) < 10 and abs(float(cells[7].rstrip("%"))) < 10  # the same picture
    assert len(list((tmp_path / "cache").glob("*.npy"))) == 2  # the reference and Mitsuba at 32 spp
    assert "| tiny | 32x24 | 0 | 0 |" in (tmp_path / "report.md").read_text()


@pytest.mark.gl
def test_the_reference_is_read_from_the_cache_the_second_time(mitsuba, renderer, tmp_path):
    from lenslab.validate.files import validate_file

    scene = tmp_path / "tiny.xml"
    scene.write_text(TINY_SCENE)
    runs = [validate_file(scene, name="tiny", spp=4, reference_spp=8, width=24, renderer=renderer,
                          cache_dir=tmp_path) for _ in range(2)]
    assert runs[0].error is None and runs[0].reference.seconds > 0 and runs[1].reference.seconds == 0
    assert np.array_equal(runs[0].reference.image, runs[1].reference.image)
    scene.write_text(TINY_SCENE.replace("0.8", "0.7"))  # a changed file is rendered again
    changed = validate_file(scene, name="tiny", spp=4, reference_spp=8, width=24, renderer=renderer, cache_dir=tmp_path)
    assert changed.reference.seconds > 0 and changed.reference.image.mean() < runs[0].reference.image.mean()


@pytest.mark.gl
def test_a_scene_that_cannot_be_rendered_is_a_row_with_its_reason(mitsuba, tmp_path, capsys):
    from lenslab.validate.cli import main

    broken = tmp_path / "broken.xml"
    broken.write_text('<scene version="3.0.0"><shape type="sphere">')  # cut short
    status = main(["--files", str(broken), "--spp", "1", "--reference-spp", "1", "--resolution", "16",
                   "--no-cache"])
    captured = capsys.readouterr()
    assert status == 1 and "Traceback" not in captured.err
    row = captured.out.splitlines()[2]
    assert row.split()[:2] == ["broken", "-"] and " ERROR " in row
    assert "Mitsuba: " in row and "LensLab: " in row and str(broken) in row


def test_the_doc_scenes_script_exports_a_commit_and_keeps_its_lists_apart(tmp_path, capsys):
    import importlib.util
    import subprocess
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "mitsuba_doc_scenes.py"
    spec = importlib.util.spec_from_file_location("mitsuba_doc_scenes", path)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    assert not set(script.SELECTED) & set(script.EXCLUDED) and len(set(script.SELECTED)) == len(script.SELECTED)

    repo = tmp_path / "data"
    (repo / "docs" / "scenes").mkdir(parents=True)
    (repo / "docs" / "scenes" / "a.xml").write_text("<scene version='3.0.0'/>")
    (repo / "elsewhere.txt").write_text("not exported")
    git = ["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    subprocess.run([*git, "add", "."], check=True)
    subprocess.run([*git, "commit", "-qm", "scenes"], check=True)
    dest = tmp_path / "out"
    assert script.main(["export", "--git-dir", str(repo / ".git"), "--dest", str(dest), "--commit", "HEAD"]) == 0
    assert (dest / "docs" / "scenes" / "a.xml").read_text() == "<scene version='3.0.0'/>"
    head = subprocess.run([*git, "rev-parse", "HEAD"], check=True, capture_output=True, text=True).stdout.strip()
    assert not (dest / "elsewhere.txt").exists() and (dest / "SOURCE").read_text().split() == [script.SOURCE_REPO, head]
    capsys.readouterr()
    assert script.main(["run", "--dest", str(dest), "--list"]) == 2  # the selected scenes are not there
    assert "not exported yet" in capsys.readouterr().err
