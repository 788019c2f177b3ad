"""Run glsl/bsdf_probe.comp: sample or evaluate one material's BSDF on the GPU, for the material tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lenslab.render.buffers import pack_material
from lenslab.render.gl import make_current
from lenslab.render.gpu_layout import (IMAGE_DATA_BINDING, MATERIAL_ROWS, MATERIALS_BINDING, PROBE_IN_BINDING,
                                       PROBE_OUT_BINDING)
from lenslab.render.textures import TextureTable

LOCAL_SIZE_X = 64


@dataclass
class Samples:
    wi: np.ndarray  # (N, 3)
    pdf: np.ndarray
    weight: np.ndarray  # (N, 3): f |cos| / pdf
    ok: np.ndarray  # sampling succeeded
    delta: np.ndarray


class BsdfProbe:
    def __init__(self, renderer, material, tmp_dir="."):
        self.renderer = renderer
        ctx = renderer.ctx
        make_current(ctx)
        textures = TextureTable(base_dir=tmp_dir)
        rows = pack_material(material, textures)
        self.materials = ctx.buffer(np.concatenate([rows, textures.records()]).astype(np.float32).tobytes())
        texels = textures.texels()
        self.image_data = ctx.buffer(texels.tobytes() if texels.size else np.zeros(4, np.uint32).tobytes())
        self.program = renderer.program("bsdf_probe.comp", LOCAL_SIZE_X=LOCAL_SIZE_X)
        self.program["texture_base"].value = MATERIAL_ROWS  # the one material's record, then its textures

    def _run(self, items: np.ndarray) -> np.ndarray:
        ctx, n = self.renderer.ctx, len(items)
        make_current(ctx)
        inp = ctx.buffer(items.astype(np.float32).tobytes())
        out = ctx.buffer(reserve=n * 32)
        self.materials.bind_to_storage_buffer(MATERIALS_BINDING)
        self.image_data.bind_to_storage_buffer(IMAGE_DATA_BINDING)
        inp.bind_to_storage_buffer(PROBE_IN_BINDING)
        out.bind_to_storage_buffer(PROBE_OUT_BINDING)
        self.program["item_count"].value = n
        self.program["probe_material"].value = 0
        self.program.run((n + LOCAL_SIZE_X - 1) // LOCAL_SIZE_X, 1, 1)
        result = np.frombuffer(out.read(), np.float32).reshape(n, 2, 4).copy()
        inp.release()
        out.release()
        return result

    def sample(self, wo, u: np.ndarray, front_face=True) -> Samples:
        n = len(u)
        items = np.zeros((n, 2, 4), np.float32)
        items[:, 0, :3], items[:, 0, 3] = wo, float(front_face)
        items[:, 1, :3] = u
        r = self._run(items)
        return Samples(r[:, 0, :3], r[:, 0, 3], r[:, 1, :3], r[:, 1, 3] > 0, r[:, 1, 3] > 1.5)

    def evaluate(self, wo, wi: np.ndarray, front_face=True) -> tuple[np.ndarray, np.ndarray]:
        """(f |cos|, pdf) for each direction wi."""
        n = len(wi)
        items = np.zeros((n, 2, 4), np.float32)
        items[:, 0, :3], items[:, 0, 3] = wo, float(front_face)
        items[:, 1, :3], items[:, 1, 3] = wi, 1.0
        r = self._run(items)
        return r[:, 1, :3], r[:, 0, 3]

    def release(self):
        self.materials.release()
        self.image_data.release()
