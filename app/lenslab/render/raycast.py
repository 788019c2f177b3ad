"""Nearest-hit ray queries on the GPU, through the renderer's own kd-tree traversal (glsl/bsp.glsl).

Click-to-focus asks "how far along the view axis is the surface under this pixel?"; the viewport asks
"which node is under this pixel?". Both are one ray here, traced by the same code as every rendered sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lenslab.render.buffers import GpuScene
from lenslab.render.gl import make_current
from lenslab.render.gpu_layout import HITS_BINDING, RAYS_BINDING

LOCAL_SIZE_X = 64


@dataclass(frozen=True)
class RayHits:
    t: np.ndarray  # (N,) float32, inf where nothing was hit
    prim: np.ndarray  # (N,) int32, -1 where nothing was hit
    barycentrics: np.ndarray  # (N, 2) float32 (triangles)
    instance: np.ndarray  # (N,) int32: the instance whose mesh group holds prim, or -1 (a world primitive)

    def nodes(self, flat, first_world_prim: int = 0) -> np.ndarray:
        """The index (into flat.nodes) of the node each ray hit, -1 where it hit nothing. A world primitive's row
        is ``first_world_prim`` past its index in ``flat`` (render/instancing.py's layout)."""
        instance_node = np.array([i.node for i in flat.instances] + [-1], np.int32)
        world = self.prim - first_world_prim
        world_node = (flat.prim_node[np.clip(world, 0, len(flat.prim_node) - 1)] if len(flat.prim_node)
                      else np.full(len(self.prim), -1, np.int32))
        node = np.where(self.instance >= 0, instance_node[self.instance], world_node)
        return np.where(self.prim >= 0, node, -1).astype(np.int32)


def cast_rays(renderer, gpu_scene: GpuScene, origins: np.ndarray, directions: np.ndarray,
              t_min: float = 0.0, t_max: float = np.inf) -> RayHits:
    """Nearest hit for each ray (origins and directions: (N, 3)); directions need not be unit length."""
    origins = np.asarray(origins, np.float32).reshape(-1, 3)
    directions = np.asarray(directions, np.float32).reshape(-1, 3)
    n = len(origins)
    if n == 0:
        return RayHits(np.zeros(0, np.float32), np.zeros(0, np.int32), np.zeros((0, 2), np.float32),
                       np.zeros(0, np.int32))
    ctx = renderer.ctx
    make_current(ctx)  # whatever context was made in this thread since (see gl.make_current)
    program = renderer.program("raycast.comp", LOCAL_SIZE_X=LOCAL_SIZE_X)
    packed = np.zeros((n, 2, 4), np.float32)
    packed[:, 0, :3], packed[:, 0, 3] = origins, t_min
    packed[:, 1, :3], packed[:, 1, 3] = directions, np.float32(min(t_max, np.finfo(np.float32).max))
    # A batch as large as a 4K picture's rays outgrows what one dispatch (65535 groups on some devices) or one
    # storage block may hold: cast it in chunks that fit both.
    limits = renderer.limits
    chunk = min(n, limits.max_work_group_count[0] * LOCAL_SIZE_X, limits.max_storage_block_bytes // packed[0].nbytes)
    out = np.empty((n, 2, 4), np.float32)
    rays = ctx.buffer(reserve=chunk * packed[0].nbytes)
    hits = ctx.buffer(reserve=chunk * out[0].nbytes)
    try:
        gpu_scene.bind()
        rays.bind_to_storage_buffer(RAYS_BINDING)
        hits.bind_to_storage_buffer(HITS_BINDING)
        # Traversal reads a few of the scene's uniforms (no lights, no environment): set those it has. The
        # trace kernel, which reads them all, is where a misspelt name is caught (Renderer.set_uniforms).
        for name, value in gpu_scene.packed.uniforms.items():
            if name in program:
                program[name].value = value
        for first in range(0, n, chunk):
            count = min(chunk, n - first)
            rays.write(packed[first:first + count].tobytes())
            program["ray_count"].value = count
            program.run((count + LOCAL_SIZE_X - 1) // LOCAL_SIZE_X, 1, 1)
            ctx.memory_barrier()
            out[first:first + count] = np.frombuffer(hits.read(count * out[0].nbytes), np.float32).reshape(count, 2, 4)
    finally:
        rays.release()
        hits.release()
    prim = out[:, 0, 1].view(np.int32).copy()
    t = np.where(prim >= 0, out[:, 0, 0], np.inf).astype(np.float32)
    return RayHits(t, prim, out[:, 0, 2:4].copy(), out[:, 1, 0].view(np.int32).copy())
