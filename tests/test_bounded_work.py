"""Bounded work for small files: a few hundred bytes must not buy minutes of work or gigabytes.

Three ways a small input once asked for too much, each now bounded before anything large is allocated:
ten coplanar disks whose kd-tree copied references without end (now a reference budget: the tree degrades,
still correct), Mitsuba ``<default>`` values that double themselves (now one line naming the parameter), and
an image larger than the device can hold (now refused up front, saying the largest that fits).
"""

from __future__ import annotations

import json
import tracemalloc

import numpy as np
import pytest

from lenslab.render.bsp import (BUILD_BYTES_PER_REF, REFS_FLOOR, REFS_PER_PRIM_LIMIT, build_kdtree,
                                reference_budget)
from lenslab.limits import SceneTooLarge
from lenslab.render.tracer import (LLVMPIPE_BUFFER_BYTES, check_image_size, largest_image_within,
                                   largest_storage_buffer)
from lenslab.scene.io.loader import open_scene
from lenslab.scene.io.mitsuba_xml import MAX_EXPANDED_VALUE_CHARS, MAX_SUBSTITUTED_CHARS, load_mitsuba_scene
from lenslab.scene.scene import SceneError
from lenslab.scene.shapes import Disk
from tests.helpers import run_cli
from tests.test_bsp_build import aimed_rays, check_leaf_contents, check_rays, triangle_bounds

# A file a user sent: ten disks of 4,096 segments, all at the origin in one plane (641 bytes as written here).
COPLANAR_DISKS = json.dumps({"lenslab_scene": 2, "nodes": [
    {"name": f"d{i}", "shape": {"type": "disk", "segments": 4096}} for i in range(10)]})


def coplanar_disks(copies: int, segments: int) -> np.ndarray:
    """(T, 3, 3) triangles: ``copies`` identical disks of ``segments`` fan triangles meeting at one centre."""
    mesh = Disk(radius=0.5, segments=segments).mesh()
    disk = mesh.vertices[mesh.faces].astype(np.float32)
    return np.concatenate([disk] * copies)


# --------------------------------------------------------------------------------------------------
# The kd-tree: a reference budget


@pytest.mark.slow
def test_a_641_byte_scene_of_coplanar_disks_builds_within_its_reference_budget(tmp_path):
    path = tmp_path / "disks.json"
    path.write_text(COPLANAR_DISKS)
    assert path.stat().st_size == 641
    flat = open_scene(str(path)).flatten()
    # Built once untraced first: loading the compiled builder's machine code (or compiling it, where another
    # process has just rewritten numba's cache) allocates megabytes once a process, which are not the build's.
    build_kdtree(flat.prim_bounds(), triangles=flat.triangles)
    tracemalloc.start()
    try:
        tree = build_kdtree(flat.prim_bounds(), triangles=flat.triangles)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    limit = REFS_PER_PRIM_LIMIT * flat.prim_count + REFS_FLOOR
    assert tree.reference_limit <= limit  # less only where memory is short
    assert len(tree.prim_refs) <= tree.reference_limit  # before: 32 M references at depth 23, then out of memory
    assert tree.budget_leaves > 0, "the budget, not the SAH, stopped this build"
    assert peak <= BUILD_BYTES_PER_REF * tree.reference_limit  # the estimate the memory check relies on
    assert set(np.unique(tree.prim_refs)) == set(range(flat.prim_count)), "every triangle is still in the tree"


def test_a_tree_held_to_a_small_budget_is_still_exact():
    rng = np.random.default_rng(12)
    tris = coplanar_disks(copies=3, segments=256)
    bounds = triangle_bounds(tris)
    unlimited = build_kdtree(bounds, triangles=tris)
    assert len(unlimited.prim_refs) > 3 * len(tris), "without a budget these disks copy references freely"
    tree = build_kdtree(bounds, triangles=tris, max_refs=2 * len(tris))
    assert len(tree.prim_refs) <= 2 * len(tris)
    assert tree.budget_leaves > 0 and tree.reference_limit == 2 * len(tris)
    assert check_leaf_contents(tree, bounds, tris) == len(tree.prim_refs)
    aimed = lambda rng, n: aimed_rays(rng, n, radius=2.0, target=0.3)  # at the disks' crowded centre
    check_rays(tree, tris, np.zeros((0, 4)), rng, n=200, rays=aimed)  # the same first hits as brute force


def test_the_budget_spends_its_references_near_the_root_first():
    tris = coplanar_disks(copies=2, segments=512)
    bounds = triangle_bounds(tris)
    tree = build_kdtree(bounds, triangles=tris, max_refs=3 * len(tris))
    # Split where splitting saves most per added reference: a better tree than none at all.
    unsplit = build_kdtree(bounds, triangles=tris, max_depth_limit=0)
    assert tree.node_count > 1 and tree.sah_cost < unsplit.sah_cost


def test_shipped_scenes_never_meet_the_budget():
    for name in ("cornell_box", "product_shot"):
        flat = open_scene(name).flatten()
        tree = build_kdtree(flat.prim_bounds(), triangles=flat.triangles)
        assert tree.budget_leaves == 0, name


def test_the_budget_shrinks_to_the_memory_there_is():
    assert reference_budget(1000) == REFS_PER_PRIM_LIMIT * 1000 + REFS_FLOOR
    assert reference_budget(1000, memory_bytes=BUILD_BYTES_PER_REF * 5000) == 5000
    assert reference_budget(1000, memory_bytes=1 << 40) == REFS_PER_PRIM_LIMIT * 1000 + REFS_FLOOR


def test_memory_too_small_for_any_tree_is_one_clear_error():
    tris = coplanar_disks(copies=1, segments=1000)
    with pytest.raises(SceneTooLarge, match=r"^building the kd-tree of 1,000 primitives needs at least 250 KiB of "
                                            r"memory, and 10 KiB is available"):
        build_kdtree(triangle_bounds(tris), triangles=tris, memory_bytes=10 * 1024)
    with pytest.raises(ValueError, match="at least the number of primitives"):
        build_kdtree(triangle_bounds(tris), triangles=tris, max_refs=999)


@pytest.mark.slow
def test_the_cli_renders_the_disks_and_says_the_tree_met_its_limit(renderer, tmp_path, capsys):
    scene = tmp_path / "disks.json"
    scene.write_text(COPLANAR_DISKS)
    status, err = run_cli(capsys, scene, "--headless", "-o", tmp_path / "x.png", "--spp", "1", "--width", "16",
                          "--height", "16")
    assert status == 0, err
    assert "the kd-tree reached its limit of" in err and "renders more slowly" in err
    assert (tmp_path / "x.png").is_file()


# --------------------------------------------------------------------------------------------------
# Mitsuba parameters that double themselves


def doubling_defaults(levels: int, use: str = '<shape type="sphere" id="$p{last}"/>') -> str:
    """A Mitsuba file whose parameter p<k> is p<k-1> twice: p<levels> is 2^(levels-1) characters."""
    lines = ['<scene version="3.0.0">', '    <default name="p1" value="x"/>']
    lines += [f'    <default name="p{k}" value="$p{k - 1}$p{k - 1}"/>' for k in range(2, levels + 1)]
    lines += ["    " + use.format(last=levels), "</scene>"]
    return "\n".join(lines) + "\n"


def test_defaults_that_double_themselves_are_one_line_naming_the_parameter(tmp_path):
    path = tmp_path / "doubling.xml"
    path.write_text(doubling_defaults(28))
    assert path.stat().st_size < 1300
    with pytest.raises(SceneError) as error:
        load_mitsuba_scene(path)
    message = str(error.value)
    # p21 is 2^20 characters, exactly the bound; p22 = "$p21$p21" is the first to pass it, at line 23.
    assert message == (f"{path}: line 23: <default>: $p21 makes \"value\" longer than "
                       f"{MAX_EXPANDED_VALUE_CHARS:,} characters (a parameter that doubles itself?)")
    assert "\n" not in message


def test_a_value_of_exactly_the_bound_still_loads(tmp_path):
    path = tmp_path / "doubling.xml"
    path.write_text(doubling_defaults(21))  # p21: 2^20 characters, used once
    scene = load_mitsuba_scene(path)
    assert scene.nodes


def test_many_uses_of_a_long_parameter_meet_the_bound_on_all_substitution(tmp_path):
    uses = MAX_SUBSTITUTED_CHARS // 2**19 + 1  # each within the bound on one value, too many together
    body = "\n".join(f'<shape type="sphere" id="s{i}_$p20"/>' for i in range(uses))
    path = tmp_path / "many.xml"
    path.write_text(doubling_defaults(20, use=body))
    assert path.stat().st_size < 3000
    with pytest.raises(SceneError, match=rf"\$p20 brings the substituted text past {MAX_SUBSTITUTED_CHARS:,} "
                                         r"characters in all"):
        load_mitsuba_scene(path)


def test_the_cli_prints_the_doubling_error_as_one_line(tmp_path, capsys):
    path = tmp_path / "doubling.xml"
    path.write_text(doubling_defaults(28))
    status, err = run_cli(capsys, path, "--headless", "-o", tmp_path / "x.png", "--spp", "1")
    assert status == 1
    assert err.startswith("lenslab: error: ") and err.count("\n") == 1 and "$p21" in err


# --------------------------------------------------------------------------------------------------
# Images larger than the device holds


def test_an_image_beyond_llvmpipes_buffers_is_refused_with_the_largest_that_fits():
    with pytest.raises(SceneTooLarge) as error:
        check_image_size(16384, 16384, LLVMPIPE_BUFFER_BYTES, memory_bytes=None)
    assert str(error.value) == ("a 16384 x 16384 image needs 4,294,967,296 bytes of accumulation buffer; this "
                                "device holds at most 16383 x 16383 (the largest storage buffer it binds is "
                                "4,294,967,295 bytes)")
    check_image_size(16383, 16383, LLVMPIPE_BUFFER_BYTES, memory_bytes=None)  # fits: no error


def test_an_image_beyond_the_memory_is_refused_naming_the_memory():
    with pytest.raises(SceneTooLarge, match=r"^a 16384 x 16384 image needs 24.0 GiB of memory \(96 bytes a pixel\); "
                                            r"this machine holds at most 8192 x 8192 \(6.0 GiB of memory is "
                                            r"available\)$"):
        check_image_size(16384, 16384, LLVMPIPE_BUFFER_BYTES, memory_bytes=96 * 8192 * 8192)


def test_the_largest_image_keeps_the_shape_and_fits():
    for width, height, most in ((16384, 16384, 2**28 - 1), (3000, 2000, 1_000_000), (100000, 3, 1000), (7, 5, 0)):
        fit_width, fit_height = largest_image_within(width, height, most)
        assert fit_width * fit_height <= most
        assert (fit_width + 1) * (fit_height + 1) > most  # nothing a pixel larger each way fits
    assert largest_image_within(3000, 2000, 1_000_000) == (1224, 816)


def test_llvmpipe_binds_more_than_it_advertises_and_other_devices_what_they_advertise(renderer):
    limits = renderer.limits
    assert largest_storage_buffer("llvmpipe (LLVM 15.0.6, 256 bits)", limits) == max(
        limits.max_storage_block_bytes, LLVMPIPE_BUFFER_BYTES)
    assert largest_storage_buffer("NVIDIA H100 80GB HBM3/PCIe/SSE2", limits) == limits.max_storage_block_bytes


def test_the_cli_refuses_16384_square_before_building_anything(renderer, tmp_path, capsys):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "--spp", "1",
                          "--width", "16384", "--height", "16384")
    assert status == 1
    assert err.startswith("lenslab: error: ") and "cornell_box/scene.json: a 16384 x 16384 image needs " in err
    assert "holds at most" in err
    assert err.count("\n") == 1 and not (tmp_path / "x.png").exists()


def test_a_session_refuses_up_front_and_on_resize(renderer, monkeypatch):
    from lenslab.render import tracer
    from lenslab.render.job import RenderJob

    scene = open_scene("cornell_box")
    monkeypatch.setattr(renderer, "largest_buffer_bytes", 16 * 1000)  # a device of 1,000 pixels

    def no_build(*args, **kwargs):
        raise AssertionError("the scene was packed before the image size was checked")

    with monkeypatch.context() as patch:
        patch.setattr(tracer, "pack_scene", no_build)
        with pytest.raises(SceneTooLarge, match=r"a 64 x 48 image .* holds at most 36 x 27 "):
            tracer.RenderSession(renderer, scene, width=64, height=48)
        scene.camera.resolution = (64, 48)  # the CLI's headless render and the studio's export: a RenderJob
        with pytest.raises(SceneTooLarge, match=r"holds at most 36 x 27 "):
            RenderJob(renderer, scene, spp=1)
    session = tracer.RenderSession(renderer, scene, width=32, height=24)
    try:
        session.width, session.height = 64, 48  # as the studio's worker resizes its viewport
        with pytest.raises(SceneTooLarge, match="holds at most 36 x 27"):
            session.reset()
    finally:
        session.release()


def test_a_relief_too_large_is_refused_before_it_is_made(capsys, tmp_path, monkeypatch):
    from lenslab.scene.shapes import Relief

    def never(self):
        raise AssertionError("the relief's mesh was made before its size was checked")

    monkeypatch.setattr(Relief, "mesh", never)
    scene = tmp_path / "sand.json"
    scene.write_text(json.dumps({"lenslab_scene": 2, "nodes": [
        {"name": "sand", "shape": {"type": "relief", "resolution": [8192, 8192]}}]}))
    status, err = run_cli(capsys, scene, "--headless", "-o", tmp_path / "x.png", "--spp", "1")
    assert status == 1 and err.count("\n") == 1
    assert f"{scene}: the shapes made in code (node 'sand' the most) make 134,184,962 triangles" in err
    assert not (tmp_path / "x.png").exists()


def test_the_triangle_limit_is_the_device_s_or_the_machine_s_whichever_is_less():
    from lenslab.render.tracer import GPU_BYTES_PER_TRIANGLE, HOST_BYTES_PER_TRIANGLE, check_triangle_count

    block = 1000 * GPU_BYTES_PER_TRIANGLE
    check_triangle_count(1000, "has", block, None)
    with pytest.raises(SceneTooLarge, match="has 1,001 triangles; the GL device's largest storage buffer .* at most 1,000"):
        check_triangle_count(1001, "has", block, None)
    with pytest.raises(SceneTooLarge, match="has 1,000 triangles; this machine's .* available memory can build at most 999"):
        check_triangle_count(1000, "has", block, 999 * HOST_BYTES_PER_TRIANGLE)
