"""The GLSL kd-tree traversal finds the same nearest hit as brute force, on triangles and spheres."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.render.buffers import GpuScene, SceneTooLarge, pack_scene
from lenslab.render.raycast import cast_rays
from lenslab.scene.flatten import FlatScene
from lenslab.scene.materials import Diffuse
from lenslab.scene.scene import ConstantEnvironment


def flat_scene(triangles: np.ndarray, spheres: np.ndarray) -> FlatScene:
    t, s = len(triangles), len(spheres)
    normals = np.repeat(np.array([[[0, 0, 1.0]]], np.float32), t, axis=0).repeat(3, axis=1)
    return FlatScene(
        triangles=triangles.astype(np.float32), triangle_normals=normals, triangle_uvs=np.zeros((t, 3, 2), np.float32),
        triangle_material=np.zeros(t, np.int32), spheres=spheres.astype(np.float32), sphere_material=np.zeros(s, np.int32),
        materials=[Diffuse()], material_names=["grey"], prim_node=np.zeros(t + s, np.int32), nodes=[],
    )


def brute_force(flat: FlatScene, origins: np.ndarray, directions: np.ndarray):
    """Nearest hit of every ray against every primitive, in float64 numpy."""
    tri = flat.triangles.astype(np.float64)
    v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    o, d = origins[:, None, :], directions[:, None, :]
    p = np.cross(d, e2[None])
    det = np.einsum("rtk,tk->rt", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - v0[None]
        b1 = np.einsum("rtk,rtk->rt", s, p) * inv
        q = np.cross(s, e1[None])
        b2 = np.einsum("rtk,rtk->rt", np.broadcast_to(d, q.shape), q) * inv
        t = np.einsum("tk,rtk->rt", e2, q) * inv
        ok = (det != 0) & (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1) & (t > 0)
    t_tri = np.where(ok, t, np.inf)

    c, r = flat.spheres[:, :3].astype(np.float64), flat.spheres[:, 3].astype(np.float64)
    f = o - c[None]
    b = np.einsum("rsk,rsk->rs", f, np.broadcast_to(d, f.shape))
    disc = b**2 - (np.einsum("rsk,rsk->rs", f, f) - r[None] ** 2)
    root = np.sqrt(np.maximum(disc, 0))
    t0, t1 = -b - root, -b + root
    t_sph = np.where(disc < 0, np.inf, np.where(t0 > 0, t0, np.where(t1 > 0, t1, np.inf)))
    t_all = np.concatenate([t_tri, t_sph], axis=1)
    return t_all.min(axis=1), np.where(np.isfinite(t_all.min(axis=1)), t_all.argmin(axis=1), -1)


def random_scene(rng, triangles=3000, spheres=40):
    centres = rng.uniform(-1, 1, (triangles, 1, 3))
    tris = centres + rng.normal(scale=0.06, size=(triangles, 3, 3))
    tris[: triangles // 10, :, 1] = -0.9  # a patch of triangles lying flat in one plane, as floors do
    sph = np.concatenate([rng.uniform(-1, 1, (spheres, 3)), rng.uniform(0.01, 0.15, (spheres, 1))], axis=1)
    return flat_scene(tris, sph)


@pytest.mark.parametrize("seed", [0, 1])
def test_kd_tree_traversal_matches_brute_force(renderer, seed):
    rng = np.random.default_rng(seed)
    flat = random_scene(rng)
    # Rays from outside and inside the scene, some exactly axis-aligned (zero direction components).
    origins = np.concatenate([rng.uniform(-2.5, 2.5, (1500, 3)), rng.uniform(-0.5, 0.5, (1500, 3))])
    directions = rng.normal(size=(3000, 3))
    directions[:300, [0, 2]] = 0.0
    directions[300:600, 1] = 0.0
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    expected_t, expected_prim = brute_force(flat, origins, directions)

    gpu = GpuScene(renderer.ctx, pack_scene(flat, ConstantEnvironment()), renderer.limits.max_storage_block_bytes)
    try:
        hits = cast_rays(renderer, gpu, origins, directions)
    finally:
        gpu.release()

    found = np.isfinite(expected_t)
    assert found.sum() > 1000  # the test exercises hits, not only misses
    assert np.array_equal(np.isfinite(hits.t), found)
    assert np.allclose(hits.t[found], expected_t[found], rtol=1e-4, atol=1e-5)
    same_prim = hits.prim[found] == expected_prim[found]
    # Where two primitives are hit at (numerically) the same distance either answer is right.
    assert same_prim.mean() > 0.995


def test_scene_too_big_for_the_device_is_refused_with_a_clear_message(renderer):
    flat = random_scene(np.random.default_rng(2), triangles=2000, spheres=0)
    packed = pack_scene(flat, ConstantEnvironment())
    with pytest.raises(SceneTooLarge, match=r"needs 125 KiB of shading in one storage buffer, more than this GL device allows \(64 KiB\).*2,000 triangles"):
        GpuScene(renderer.ctx, packed, max_block_bytes=64 * 1024)


def test_a_floor_rotated_into_place_is_found_by_rays_that_reach_it(renderer):
    """A disk turned -90 degrees about x lies at y = 1e-16-ish, not 0: the tree splits it at planes a rounding
    error apart, which a ray reaches at the same float t. Traversal must visit both sides of such a tie
    (validation scene environment_depths rendered 10% too dark when it did not)."""
    from lenslab.scene.scene import Node, Scene
    from lenslab.scene.shapes import Disk, Sphere
    from lenslab.scene.transform import Transform

    scene = Scene(nodes=[
        Node("ground", Transform(rotate_deg=(-90, 0, 0), scale=(30, 30, 30)), Disk(radius=1.0), "grey"),
        Node("ball", Transform(translate=(0.5, 0.6, -5)), Sphere(radius=0.6), "grey"),
    ], materials={"grey": Diffuse()})
    flat = scene.flatten()
    assert 0 < np.abs(flat.triangles[..., 1]).max() < 1e-5  # the premise: almost, not exactly, flat
    rng = np.random.default_rng(4)
    n = 4000
    directions = rng.normal(size=(n, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    from_eye = np.tile([0.0, 1.0, 0.0], (n, 1))
    from_floor = np.stack([rng.uniform(-8, 8, n), np.full(n, 1e-4), rng.uniform(-14, 2, n)], axis=1)
    gpu = GpuScene(renderer.ctx, pack_scene(flat, ConstantEnvironment()), renderer.limits.max_storage_block_bytes)
    try:
        for origins in (from_eye, from_floor):
            hits = cast_rays(renderer, gpu, origins, directions)
            expected_t, _ = brute_force(flat, origins, directions)
            assert np.isfinite(expected_t).sum() > n // 3
            assert np.array_equal(np.isfinite(hits.t), np.isfinite(expected_t))
    finally:
        gpu.release()


def test_a_batch_larger_than_one_dispatch_is_cast_in_chunks(renderer, monkeypatch):
    # A 4K picture's rays exceed the 65535 work groups some devices allow in one dispatch. Pretend this device
    # allows 3 groups (192 rays): a batch of 1000 must come back whole and in order, as one dispatch gives it
    # where the device allows one.
    import dataclasses

    rng = np.random.default_rng(7)
    flat = random_scene(rng, triangles=2000, spheres=20)
    origins = rng.uniform(-0.5, 0.5, (1000, 3))
    directions = rng.normal(size=(1000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    expected_t, _ = brute_force(flat, origins, directions)

    gpu = GpuScene(renderer.ctx, pack_scene(flat, ConstantEnvironment()), renderer.limits.max_storage_block_bytes)
    try:
        whole = cast_rays(renderer, gpu, origins, directions)
        monkeypatch.setattr(renderer, "limits", dataclasses.replace(renderer.limits, max_work_group_count=(3, 1, 1)))
        chunked = cast_rays(renderer, gpu, origins, directions)
    finally:
        gpu.release()

    found = np.isfinite(expected_t)
    assert found.sum() > 500  # hits in every chunk
    np.testing.assert_array_equal(chunked.prim, whole.prim)
    np.testing.assert_array_equal(chunked.t, whole.t)
    np.testing.assert_allclose(chunked.t[found], expected_t[found], rtol=1e-4, atol=1e-5)
