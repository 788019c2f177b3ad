"""Built kd-trees kept on disk (render/kdtree_cache.py): the same primitives give back the same tree, anything that
changes the tree makes a new one, and a cache that cannot be read or written never stops a render."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.render import kdtree_cache
from lenslab.render.bsp import build_kdtree

MEMORY = 8 * 1024**3


@pytest.fixture(autouse=True)
def small_scenes_count(monkeypatch):
    monkeypatch.setattr(kdtree_cache, "MIN_PRIMITIVES", 100)


def random_triangles(count, seed=0):
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-10.0, 10.0, (count, 1, 3))
    return (centres + rng.normal(0.0, 0.3, (count, 3, 3))).astype(np.float32)


def boxes(triangles):
    return np.stack([triangles.min(axis=1), triangles.max(axis=1)], axis=1)


def cached(triangles, folder, **options):
    return kdtree_cache.kdtree(boxes(triangles), triangles=triangles, folder=folder, memory_bytes=MEMORY, **options)


def assert_same_tree(a, b):
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.prim_refs, b.prim_refs)
    assert np.array_equal(a.bounds, b.bounds)
    assert (a.max_depth, a.node_count, a.leaf_count, a.sah_cost, a.reference_limit) == \
           (b.max_depth, b.node_count, b.leaf_count, b.sah_cost, b.reference_limit)
    assert a.params == b.params


def test_the_same_primitives_read_back_the_tree_they_built(tmp_path):
    triangles = random_triangles(2000)
    first = cached(triangles, tmp_path)
    second = cached(triangles, tmp_path)
    assert not first.from_cache and second.from_cache
    assert_same_tree(first, second)
    assert_same_tree(second, build_kdtree(boxes(triangles), triangles=triangles, memory_bytes=MEMORY))
    assert len(list(tmp_path.glob("*.npz"))) == 1


def test_a_moved_triangle_or_other_build_constants_make_a_new_tree(tmp_path):
    triangles = random_triangles(2000)
    cached(triangles, tmp_path)
    moved = triangles.copy()
    moved[17, 1, 0] += 0.5
    assert not cached(moved, tmp_path).from_cache
    assert not cached(triangles, tmp_path, leaf_prims=3).from_cache
    assert cached(triangles, tmp_path, threads=1).from_cache  # threads build the same tree: not in the key
    assert len(list(tmp_path.glob("*.npz"))) == 3


def test_a_new_builder_makes_new_keys(tmp_path, monkeypatch):
    triangles = random_triangles(500)
    cached(triangles, tmp_path)
    monkeypatch.setattr(kdtree_cache, "_builder_fingerprint", lambda: b"the builder changed")
    assert not cached(triangles, tmp_path).from_cache


def test_small_scenes_are_built_without_the_cache(tmp_path, monkeypatch):
    monkeypatch.setattr(kdtree_cache, "MIN_PRIMITIVES", 5000)
    triangles = random_triangles(2000)
    cached(triangles, tmp_path)
    assert not cached(triangles, tmp_path).from_cache
    assert not list(tmp_path.iterdir())


def test_a_damaged_file_is_built_again_and_replaced(tmp_path):
    triangles = random_triangles(1000)
    built = cached(triangles, tmp_path)
    (file,) = tmp_path.glob("*.npz")
    file.write_bytes(file.read_bytes()[:1000])  # cut short, as by a full disk or a killed writer
    again = cached(triangles, tmp_path)
    assert not again.from_cache
    assert_same_tree(built, again)
    assert cached(triangles, tmp_path).from_cache


def test_the_cache_can_be_turned_off_or_moved(tmp_path, monkeypatch):
    triangles = random_triangles(500)
    monkeypatch.setenv("LENSLAB_KDTREE_CACHE", "off")
    assert kdtree_cache.cache_dir() is None
    kdtree_cache.kdtree(boxes(triangles), triangles=triangles)
    assert not kdtree_cache.kdtree(boxes(triangles), triangles=triangles).from_cache
    monkeypatch.setenv("LENSLAB_KDTREE_CACHE", str(tmp_path / "trees"))
    kdtree_cache.kdtree(boxes(triangles), triangles=triangles)
    assert kdtree_cache.kdtree(boxes(triangles), triangles=triangles).from_cache
    assert len(list((tmp_path / "trees").glob("*.npz"))) == 1


def test_a_folder_that_cannot_be_written_costs_only_the_keeping(tmp_path):
    blocker = tmp_path / "a file, not a folder"
    blocker.write_text("")
    triangles = random_triangles(500)
    tree = cached(triangles, blocker / "trees")
    assert tree.node_count > 1 and not tree.from_cache


def test_the_least_recently_used_trees_go_first(tmp_path, monkeypatch):
    import os

    sets = [random_triangles(800, seed) for seed in range(3)]
    cached(sets[0], tmp_path)
    size = next(tmp_path.glob("*.npz")).stat().st_size
    monkeypatch.setattr(kdtree_cache, "MAX_CACHE_BYTES", int(2.5 * size))
    cached(sets[1], tmp_path)
    for age, file in enumerate(sorted(tmp_path.glob("*.npz"), key=lambda f: f.stat().st_mtime)):
        os.utime(file, (1e9 + age, 1e9 + age))  # distinct times: the first set is the oldest
    assert cached(sets[0], tmp_path).from_cache  # reading it makes it the newest
    cached(sets[2], tmp_path)  # a third tree passes the limit: the one used least recently (set 1) goes
    assert len(list(tmp_path.glob("*.npz"))) == 2
    assert cached(sets[0], tmp_path).from_cache and cached(sets[2], tmp_path).from_cache
    assert not cached(sets[1], tmp_path).from_cache


def test_a_tree_is_used_again_only_within_todays_reference_budget(tmp_path):
    triangles = random_triangles(3000)
    roomy = cached(triangles, tmp_path)
    assert roomy.budget_leaves == 0
    refs = len(roomy.prim_refs)
    # Memory for fewer references than that tree holds: a build today would stop short, so it is built again.
    tight_memory = (refs - 500) * 256
    tight = kdtree_cache.kdtree(boxes(triangles), triangles=triangles, folder=tmp_path, memory_bytes=tight_memory)
    assert not tight.from_cache and tight.budget_leaves > 0 and len(tight.prim_refs) <= refs - 500
    again = kdtree_cache.kdtree(boxes(triangles), triangles=triangles, folder=tmp_path, memory_bytes=tight_memory)
    assert again.from_cache and again.budget_leaves > 0  # the same budget: the cut tree is today's tree
    # With room again, the cut tree is not what a build makes now: the full one is built again.
    roomy_again = cached(triangles, tmp_path)
    assert not roomy_again.from_cache and roomy_again.budget_leaves == 0
    assert_same_tree(roomy, roomy_again)


@pytest.mark.gl
def test_the_cli_says_when_the_tree_came_from_the_cache(renderer, tmp_path, capsys, monkeypatch):
    import lenslab.cli
    from tests.test_output_faults import run_cli

    monkeypatch.setattr(kdtree_cache, "MIN_PRIMITIVES", 1)
    monkeypatch.setenv("LENSLAB_KDTREE_CACHE", str(tmp_path / "trees"))
    monkeypatch.setattr(lenslab.cli, "PROGRESS_LINE_SECONDS", 0.0)
    args = ["cornell_box", "--headless", "-o", tmp_path / "x.png", "--spp", "1", "--width", "16", "--height", "16"]
    loaded = []
    for _ in range(2):
        status, err = run_cli(capsys, *args)
        assert status == 0, err
        loaded.append(next(line for line in err.splitlines() if line.startswith("lenslab: loaded:")))
    assert "nodes built in" in loaded[0] and "nodes read from the cache in" in loaded[1]


def test_trees_and_mitsubas_references_share_the_users_cache_folder(tmp_path, monkeypatch):
    from lenslab.validate.files import default_cache_dir

    monkeypatch.delenv("LENSLAB_KDTREE_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert kdtree_cache.cache_dir() == tmp_path / "lenslab" / "kdtrees"
    assert default_cache_dir() == tmp_path / "lenslab" / "validate"


def test_a_write_that_fails_on_a_full_disk_leaves_no_partial_file(tmp_path, monkeypatch):
    """np.savez on a full disk creates its file and then fails: the 0-byte ``.partial.npz`` it left was never
    cleaned (eviction counts bytes, and it has none)."""
    import errno

    def full_disk(file, **arrays):
        open(file, "wb").close()  # as a real write does: the file is made, then its first block is refused
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(kdtree_cache.np, "savez", full_disk)
    tree = cached(random_triangles(500), tmp_path)
    assert tree.node_count > 1 and not tree.from_cache  # the render goes on
    assert list(tmp_path.iterdir()) == []


def test_an_interrupted_write_takes_its_partial_file_with_it(tmp_path, monkeypatch):
    def interrupted(file, **arrays):
        open(file, "wb").close()
        raise KeyboardInterrupt

    monkeypatch.setattr(kdtree_cache.np, "savez", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cached(random_triangles(500), tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_partial_files_of_writers_that_are_gone_are_swept(tmp_path):
    """A writer killed mid-write (SIGKILL, a power cut) runs no clean-up: the next write sweeps what it left,
    and never a partial file of a writer still running."""
    import os
    import subprocess
    import sys
    import time

    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()  # a process number no process has now
    dead = tmp_path / f".{'a' * 40}.{child.pid}.partial.npz"
    alive = tmp_path / f".{'b' * 40}.{os.getppid()}.partial.npz"
    old = tmp_path / f".{'c' * 40}.{os.getppid()}.partial.npz"  # another machine's, say: its age tells
    for path in (dead, alive, old):
        path.write_bytes(b"")
    then = time.time() - 2 * 3600
    os.utime(old, (then, then))
    cached(random_triangles(500), tmp_path)
    assert not dead.exists() and not old.exists() and alive.exists()
    assert len(list(tmp_path.glob("*.npz"))) == 2  # the tree written, and the live writer's partial file
