"""The benchmark scripts run end to end on a tiny size (their figures are for people, never asserted)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"

# Each runs a whole script in a process of its own, the slow tier's kind of test (docs/testing.md).
pytestmark = pytest.mark.slow


def run(script, *args, tmp_path):
    result = subprocess.run([sys.executable, str(BENCHMARKS / script), *map(str, args)], capture_output=True,
                            text=True, timeout=600, cwd=tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    return result.stdout


@pytest.mark.gl
def test_vs_mitsuba_renders_every_scene_with_both_samplers(renderer, tmp_path):
    out = run("vs_mitsuba.py", "--lenslab-only", "--res", 12, "--spp", 2, "--seeds", 2, "--triangles", 2000,
              "--cache", tmp_path / "cache", tmp_path=tmp_path)
    rows = [line.split() for line in out.splitlines() if line.split()[:1] and line.split()[0] in
            ("cornell_dof", "dof_lights", "glass_metal_envmap", "million_triangles")]
    assert {(row[0], row[2]) for row in rows} == {(scene, sampler) for scene in
                                                   ("cornell_dof", "dof_lights", "glass_metal_envmap", "million_triangles")
                                                   for sampler in ("independent", "sobol")}
    assert all(float(row[3]) > 0 and float(row[4]) > 0 and float(row[5]) > 0 for row in rows)  # cold, warm, rate
    assert list((tmp_path / "cache").glob("torus_outward_2000.ply"))


@pytest.mark.gl
def test_real_lens_prints_a_cost_per_lens_and_depth(renderer, tmp_path):
    out = run("real_lens.py", "--seconds", 0.05, "--size", 16, "--rounds", 1, tmp_path=tmp_path)
    rows = [line.split() for line in out.splitlines() if line[:1].isdigit()]
    assert len(rows) == 8 and all(float(row[-1]) > 0 for row in rows)  # four lenses, two depths; a table time


@pytest.mark.gl
def test_render_throughput_prints_a_figure_per_scene_and_depth(renderer, tmp_path):
    out = run("render_throughput.py", "--seconds", 0.05, "--size", 16, tmp_path=tmp_path)
    assert out.count("cornell_box") == 5 and out.count("dof_chart") == 5


@pytest.mark.gl
def test_batch_scaling_prints_shots_per_minute_with_and_without_the_engine(renderer, tmp_path):
    out = run("batch_scaling.py", "--shots", 2, "--size", 8, "--spp", 1, tmp_path=tmp_path)
    for row in ("no engine (this process)", "Dask, 1 worker", "Dask, 2 workers"):
        line = next(line for line in out.splitlines() if line.startswith(row))
        assert float(line.split()[-2]) > 0  # shots per minute
    assert "engine cost per shot" in out and "split across 2 workers" in out


@pytest.mark.gl
def test_denoise_convergence_prints_seconds_per_scene_and_metric(renderer, tmp_path):
    pytest.importorskip("pyoidn")
    out = run("denoise_convergence.py", "--size", 16, "--seconds", 0.2, "--reference-spp", 4, "--scenes",
              "cornell_box,dof_chart", "--cache", tmp_path / "cache", "--denoise-sizes", "16x16", tmp_path=tmp_path)
    rows = [line.split() for line in out.splitlines() if line.split()[:1] in (["cornell_box"], ["dof_chart"])]
    assert len(rows) == 8 and {row[2] for row in rows} == {"relMSE", "display"}  # two thresholds each
    assert len(list((tmp_path / "cache").glob("denoise_reference_*.npy"))) == 2
    assert "16x16" in out and "Open Image Denoise" in out


@pytest.mark.gl
def test_studio_edits_times_each_edit_with_two_levels_and_one(renderer, tmp_path):
    out = run("studio_edits.py", "--scenes", "cornell_ball", "--triangles", 20000, "--width", 16, "--repeat", 1, "--spp", 1,
              "--cache", tmp_path / "cache", tmp_path=tmp_path)
    rows = {line.split("  ")[0].strip(): line.split() for line in out.splitlines()
            if line.startswith(("open", "material", "move", "hide"))}
    assert set(rows) == {"open", "material", "move small", "move large", "hide small"}
    for edit, row in rows.items():
        numbers = [word for word in row if word.endswith("s") and word[:-1].replace(".", "").isdigit()]
        assert len(numbers) == 2 and all(float(n[:-1]) > 0 for n in numbers), (edit, row)
    # With two levels the opening builds the ball's tree, and no edit after it does (the last column).
    assert rows["open"][-1] == "1" and all(row[-1] == "0" for edit, row in rows.items() if edit != "open"), out
    assert "M samples/s with two levels" in out


@pytest.mark.gl
def test_mesh_open_prints_a_rate_for_every_format_and_step(tmp_path):
    out = run("mesh_open.py", "--triangles", 2000, "--repeat", 1, tmp_path=tmp_path)
    steps = ("read ply", "read ply-ascii", "read obj", "read glb", "read serialized", "place (a mesh group)",
             "kd-tree, compiled build", "kd-tree, levels build", "pack rows")
    for step in steps:
        line = next(line for line in out.splitlines() if line.startswith(step))
        assert float(line.split()[-1]) > 0 and float(line.split()[-2]) >= 0, line  # rate, seconds


@pytest.mark.gl
def test_instances_scale_places_a_grid_of_one_mesh_and_stores_it_once(renderer, tmp_path):
    out = run("instances_scale.py", "--grid", 3, "--triangles", 20000, "--width", 12, "--spp", 1, "--cache",
              tmp_path / "cache", tmp_path=tmp_path)
    line = next(line for line in out.splitlines() if line.startswith("9 balls"))
    placed, stored = (int(line.split()[k].replace(",", "")) for k in (2, 5))
    assert placed == 9 * (stored - 2) + 2 and "1 mesh trees" in line  # the floor's two triangles, once
    assert "M samples/s" in out


@pytest.mark.gl
def test_edit_to_clean_times_every_edit_and_counts_raw_pictures(renderer, tmp_path):
    pytest.importorskip("pyoidn")
    out = run("edit_to_clean.py", "--width", 24, "--height", 16, "--seconds", 1, "--reference-spp", 4,
              "--cache", tmp_path, tmp_path=tmp_path)
    rows = [line.split("|")[1:-1] for line in out.splitlines() if line.startswith("| f") or line.startswith("| focus")]
    assert len(rows) == 3
    assert all(cells[-1].strip() == "0" for cells in rows)  # no raw picture shown with the denoiser on
    assert len(list(tmp_path.glob("edit_reference_*.npy"))) == 3


def test_the_convergence_errors_compare_pictures_as_the_camera_exposes_them(monkeypatch):
    # relMSE's 0.01 and the display MAE assume the picture's scale (middle grey 0.18); a scene lit in nits has
    # radiance in the hundreds, which only the camera's exposure brings there.
    import dataclasses

    import numpy as np

    from lenslab.scene.io.loader import open_scene

    monkeypatch.syspath_prepend(str(BENCHMARKS))
    from denoise_convergence import camera_exposure_of

    scene = open_scene("cornell_box")
    camera = scene.camera
    assert camera.exposure_mode == "physical"
    halves = np.full((2, 4, 4, 3), 100.0, np.float32)  # 100 cd/m^2 everywhere
    light = camera.aperture(scene.base_dir()).light_fraction
    assert camera_exposure_of(scene, halves) == pytest.approx(camera.exposure_scale(light))
    compensated = dataclasses.replace(scene, camera=dataclasses.replace(camera, exposure_mode="compensated"))
    assert camera_exposure_of(compensated, halves) == 1.0
    auto = dataclasses.replace(scene, camera=dataclasses.replace(camera, exposure_mode="auto"))
    assert 100.0 * camera_exposure_of(auto, halves) == pytest.approx(0.18, rel=0.01)  # the meter's middle grey


@pytest.mark.gl
def test_studio_edit_latency_times_each_edit_in_the_window(renderer, tmp_path, monkeypatch):
    pytest.importorskip("pyoidn")
    monkeypatch.setenv("QT_QPA_PLATFORM", "offscreen")
    out = run("studio_edit_latency.py", "--repeat", 1, tmp_path=tmp_path)
    rows = [line.split("|")[1:-1] for line in out.splitlines() if line.startswith(("| f", "| focus"))]
    assert len(rows) == 3
    for cells in rows:
        assert float(cells[1].split()[0]) > 0 and float(cells[3].split()[0]) > 0  # seconds, first and full
        assert cells[-1].strip() == "0"  # no raw picture shown with the denoiser on
