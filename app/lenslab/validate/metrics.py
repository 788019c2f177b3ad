"""The figures ``lenslab validate`` reports, in numpy alone.

* **Block bias**: the image cut into 16 x 16 blocks; each block's mean (over pixels and the three channels)
  against the reference's, as a relative difference ``(mean - ref) / ref``. Blocks darker than 1% of the
  reference image's mean are left out (a relative figure means nothing there; their absolute error is
  still in the relative MSE). Reported: the largest, the median and the 95th-percentile absolute block bias.
* **Total light**: the sum of an image over the reference's, less one: ``+0.01`` is 1% more light in all.
* **Relative MSE**: ``mean((x - ref)^2 / (ref^2 + eps))`` over pixels and channels, with eps = 0.01, the
  usual guard against division by near-black reference pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BLOCK = 16
DARK_FRACTION = 0.01
REL_MSE_EPS = 1e-2


def block_means(image: np.ndarray, block: int = BLOCK) -> np.ndarray:
    """(H // block, W // block) means over each block's pixels and channels (a partial edge block is dropped)."""
    image = np.asarray(image, np.float64)
    if image.ndim == 3:
        image = image.mean(axis=2)
    h, w = image.shape[0] // block, image.shape[1] // block
    if h == 0 or w == 0:
        raise ValueError(f"an image of {image.shape[1]} x {image.shape[0]} holds no {block} x {block} block")
    return image[: h * block, : w * block].reshape(h, block, w, block).mean(axis=(1, 3))


def block_bias(image: np.ndarray, reference: np.ndarray, block: int = BLOCK) -> np.ndarray:
    """Relative bias of each block's mean; NaN where the reference block is darker than 1% of its image mean."""
    test, ref = block_means(image, block), block_means(reference, block)
    floor = DARK_FRACTION * float(np.mean(reference))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ref > floor, (test - ref) / ref, np.nan)


@dataclass(frozen=True)
class BiasSummary:
    max_abs: float  # the most biased block, as a fraction (0.02 = 2%)
    median_abs: float
    blocks: int  # blocks counted (bright enough to judge)
    p95_abs: float = float("nan")  # the 95th percentile: the worst blocks but for a few

    def meets(self, max_allowed: float = 0.02, median_allowed: float = 0.01) -> bool:
        return self.max_abs <= max_allowed and self.median_abs <= median_allowed


def summarize_bias(bias: np.ndarray) -> BiasSummary:
    values = np.abs(bias[np.isfinite(bias)])
    if values.size == 0:
        return BiasSummary(float("nan"), float("nan"), 0)
    return BiasSummary(float(values.max()), float(np.median(values)), int(values.size),
                       float(np.percentile(values, 95)))


def total_light(image: np.ndarray, reference: np.ndarray) -> float:
    """``sum(image) / sum(reference) - 1`` over pixels and channels: how much more (or less) light in all."""
    image, reference = np.asarray(image, np.float64), np.asarray(reference, np.float64)
    if image.shape != reference.shape:
        raise ValueError(f"image {image.shape} and reference {reference.shape} differ in shape")
    total = float(reference.sum())
    return float(image.sum()) / total - 1.0 if total > 0 else float("nan")


def relative_mse(image: np.ndarray, reference: np.ndarray, eps: float = REL_MSE_EPS) -> float:
    image, reference = np.asarray(image, np.float64), np.asarray(reference, np.float64)
    if image.shape != reference.shape:
        raise ValueError(f"image {image.shape} and reference {reference.shape} differ in shape")
    return float(np.mean((image - reference) ** 2 / (reference**2 + eps)))
