"""The table ``lenslab validate`` prints, the side-by-side PNGs and docs/validation.md."""

from __future__ import annotations

import math
import os
import platform
from pathlib import Path

import numpy as np

from lenslab.validate.metrics import BiasSummary

HEADER = ("scene", "size", "bias max M", "bias med M", "bias max L", "bias med L", "relMSE M", "relMSE L",
          "time M", "time L", "goal")
DIFF_RANGE = 0.2  # the difference image shows (LensLab - reference) / reference mean, full colour at 20%
OWN_SCENES_HEADING = "## Mitsuba's own scenes"  # docs/validation.md's section on --files runs, kept by write_docs


def _pct(value: float) -> str:
    return "n/a" if value != value else f"{100 * value:.2f}%"


def _sci(value: float) -> str:
    return "n/a" if value != value or math.isinf(value) else f"{value:.3g}"


def row(result) -> tuple[str, ...]:
    w, h = result.resolution
    return (result.name, f"{w}x{h}", _pct(result.mitsuba_bias.max_abs), _pct(result.mitsuba_bias.median_abs),
            _pct(result.lenslab_bias.max_abs), _pct(result.lenslab_bias.median_abs), _sci(result.mitsuba_rel_mse),
            _sci(result.lenslab_rel_mse), f"{result.mitsuba.seconds:.1f} s", f"{result.lenslab.seconds:.1f} s",
            "met" if result.meets_goal else "MISSED")


def format_table(rows: list[tuple[str, ...]], header: tuple[str, ...] = HEADER) -> str:
    """A plain-text table, columns padded to their widest cell."""
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(str(c).ljust(w) for c, w in zip(r, widths)).rstrip() for r in [header, *rows]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(rows: list[tuple[str, ...]], header: tuple[str, ...] = HEADER) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def _write_png(path: Path, rgb8: np.ndarray) -> None:
    import OpenImageIO as oiio

    from lenslab.render.film import write_pixels

    spec = oiio.ImageSpec(rgb8.shape[1], rgb8.shape[0], 3, oiio.UINT8)
    write_pixels(path, np.ascontiguousarray(rgb8), spec)  # whole or not at all, as every image LensLab writes


def display(linear: np.ndarray) -> np.ndarray:
    """Mitsuba's image and ours side by side, both through the default view transform (ACES 2.0 SDR on sRGB)."""
    from lenslab.render.film import display_pixels, to_8bit

    return to_8bit(display_pixels(linear))


def difference_image(image: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Red where LensLab is brighter, blue where darker; full colour at DIFF_RANGE of the reference's mean."""
    d = (image.mean(axis=2) - reference.mean(axis=2)) / max(float(reference.mean()), 1e-12)
    t = np.clip(d / DIFF_RANGE, -1, 1)
    rgb = np.stack([np.where(t > 0, 1.0, 1 + t), 1 - np.abs(t), np.where(t < 0, 1.0, 1 - t)], axis=-1)
    return np.clip(np.round(rgb * 255), 0, 255).astype(np.uint8)


def write_images(result, folder: Path) -> dict[str, str]:
    folder.mkdir(parents=True, exist_ok=True)
    files = {}
    for kind, rgb8 in (("mitsuba", display(result.reference.image)), ("lenslab", display(result.lenslab_converged.image)),
                       ("difference", difference_image(result.lenslab_converged.image, result.reference.image))):
        path = folder / f"{result.name}-{kind}.png"
        _write_png(path, rgb8)
        files[kind] = path.name
    return files


def machine_description(renderer=None) -> list[str]:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    lines = [f"CPU: {cpu}, {os.cpu_count()} logical cores; {platform.system()} {platform.release()}"]
    if renderer is not None:
        info = renderer.describe()
        lines.append(f"LensLab GL renderer: {info.get('renderer')} ({info.get('version')})")
    try:
        import mitsuba

        from lenslab.validate.mitsuba_env import VARIANT

        lines.append(f"Mitsuba {mitsuba.__version__}, variant {VARIANT}")
    except ImportError:
        pass
    return lines


def write_docs(results, docs_dir: Path, *, spp: int, reference_spp: int, bias_spp: int, renderer=None,
               notes: str = "") -> Path:
    image_dir = docs_dir / "validation"
    sections = []
    for result in results:
        files = write_images(result, image_dir)
        sections.append(
            f"### {result.name}\n\n| Mitsuba 3 ({result.reference.spp} spp) | LensLab ({result.lenslab_converged.spp} spp) "
            f"| difference |\n| --- | --- | --- |\n| ![](validation/{files['mitsuba']}) | ![](validation/{files['lenslab']}) "
            f"| ![](validation/{files['difference']}) |\n"
            + ("\nImporter notes: " + "; ".join(w.split(': ', 1)[-1] for w in result.warnings) + "\n" if result.warnings else ""))
    from lenslab import __version__

    text = f"""# Validation against Mitsuba 3

Made by `lenslab validate --spp {spp} --reference-spp {reference_spp} --bias-spp {bias_spp} --write-docs`
(LensLab {__version__}); the scenes are Mitsuba XML files in `app/lenslab/validate/scenes/`, read by LensLab's
importer exactly as `lenslab scene.xml --headless` reads them, and by Mitsuba with `mi.load_file`.

Machine: {'; '.join(machine_description(renderer))}.

## How the figures are made

- **Reference**: Mitsuba 3 at {reference_spp} samples per pixel (independent sampler, its own seeds).
- **Bias**: each renderer at {bias_spp} spp (seeds unlike the reference's), the image cut into 16 x 16 pixel
  blocks, each block's mean against the reference's: `|mean - ref| / ref` (blocks darker than 1% of the
  image mean are left out). *max* is the worst block, *med* the median. Mitsuba's own columns (M) show how
  far noise alone goes at these sample counts: a LensLab (L) figure near them is noise, not bias.
- **relMSE**: at equal samples ({spp} spp each), `mean((x - ref)^2 / (ref^2 + 0.01))` over pixels and
  channels. The goal is LensLab's no larger than Mitsuba's.
- **time**: wall seconds of the {spp}-spp render, loading and kernel compilation included.
- **goal**: no block biased by more than 2%, median block bias under 1%, LensLab's relMSE no
  larger than Mitsuba's.

## Results

{markdown_table([row(r) for r in results])}

{notes}
## Images

Difference: red where LensLab is brighter than the reference, blue where darker, full colour at
{int(DIFF_RANGE * 100)}% of the reference's mean.

""" + "\n".join(sections)
    docs_dir.mkdir(parents=True, exist_ok=True)
    path = docs_dir / "validation.md"
    if path.is_file():  # the --files section is written by hand from its own run: kept
        old = path.read_text(encoding="utf-8")
        at = old.find("\n" + OWN_SCENES_HEADING)
        if at >= 0:
            text = text.rstrip("\n") + "\n\n" + old[at + 1:]
    path.write_text(text, encoding="utf-8")
    return path


# ---------------------------------------------------------------------------------------------------------
# --files: any scene files against the --files goal (nothing dropped, image within 2%: validate/files.py)
# ---------------------------------------------------------------------------------------------------------
FILES_HEADER = ("scene", "size", "warnings", "drops", "block med", "block p95", "noise med", "total light", "goal",
                "why")


def _signed_pct(value: float) -> str:
    return "n/a" if value != value else f"{100 * value:+.2f}%"


def files_row(result) -> tuple[str, ...]:
    lb, mb = result.lenslab_bias, result.mitsuba_bias
    size = "%dx%d" % result.resolution if result.resolution else "-"
    why = result.error if result.error is not None else ", ".join(result.reasons())
    return (result.name, size, str(len(result.warnings)), str(len(result.drops)),
            _pct(lb.median_abs) if lb else "n/a", _pct(lb.p95_abs) if lb else "n/a",
            _pct(mb.median_abs) if mb else "n/a", _signed_pct(result.total_light), result.verdict, why)


def _legend(spp: int, reference_spp: int) -> str:
    from lenslab.validate.files import GOAL_MEDIAN, GOAL_TOTAL_LIGHT

    return (f"LensLab at {spp} spp against Mitsuba 3 at {reference_spp} spp. block med / p95: the median and 95th "
            f"percentile of |16x16 block mean - reference| / reference; noise med: Mitsuba's own at {spp} spp (what "
            f"noise alone gives); total light: LensLab's sum over the reference's, less one. PASS: nothing dropped, "
            f"block med <= {100 * GOAL_MEDIAN:g}% and |total light| <= {100 * GOAL_TOTAL_LIGHT:g}%.")


def _failing(results) -> dict[str, list[str]]:
    return {r.name: r.warnings for r in results if r.verdict != "PASS"}


def _refused(results) -> dict[str, str]:
    """The scenes Mitsuba rendered and LensLab would not open or render: name -> LensLab's reason."""
    prefix = "LensLab: "
    return {r.name: r.error[len(prefix):] for r in results
            if r.error and r.reference is not None and r.error.startswith(prefix)}


def format_files_report(results, *, spp: int, reference_spp: int) -> str:
    """The table, each scene's warnings (one a line, its kind first), and the missing features ranked."""
    from lenslab.validate import findings

    lines = [format_table([files_row(r) for r in results], FILES_HEADER), "", _legend(spp, reference_spp)]
    for r in results:
        if r.warnings:
            lines += ["", f"{r.name}: {len(r.warnings)} warning{'s' if len(r.warnings) != 1 else ''}"]
            lines += [f"  {findings.kind_of(w)}: {w}" for w in r.warnings]
    ranked = findings.rank_missing_features(_failing(results), _refused(results))
    if ranked:
        lines += ["", "Missing features, by the number of scenes short of the goal that they appear in "
                  "(whole: how many would then open with nothing dropped):"]
        for m in ranked:
            lines.append(f"  {len(m.scenes):3d} scene{'s' if len(m.scenes) != 1 else ' '}  whole {len(m.sole_blocker):3d}  {m.kind:12s}  {m.feature}")
            lines.append(f"      {', '.join(m.scenes)}")
    return "\n".join(lines)


def _md(text: str) -> str:
    return text.replace("|", "\\|").replace("<", "&lt;").replace(">", "&gt;")


def markdown_files_report(results, *, spp: int, reference_spp: int) -> str:
    """The same for docs/validation.md: the table, per scene what LensLab drops or approximates (each feature
    once, with how many elements), and the missing features ranked."""
    from collections import Counter

    from lenslab.validate import findings

    rows = [tuple(_md(c) for c in files_row(r)) for r in results]
    out = [markdown_table(rows, FILES_HEADER), "", _legend(spp, reference_spp), ""]
    described = [r for r in results if any(f.kind != findings.NOTES for f in findings.findings(r.warnings))]
    if described:
        out += ["**What LensLab drops or approximates, per scene** (each element counted once):", ""]
        for r in described:
            groups = []
            for kind in (findings.DROPS, findings.APPROXIMATES):
                counts = Counter(f.feature for f in findings.findings(r.warnings) if f.kind == kind)
                if counts:
                    groups.append(f"{kind}: " + "; ".join(f"`{f}`" + (f" (x{n})" if n > 1 else "")
                                                          for f, n in counts.items()))
            out.append(f"- **{_md(r.name)}**: " + ". ".join(groups))
        out.append("")
    ranked = findings.rank_missing_features(_failing(results), _refused(results))
    if ranked:
        out += ["**Missing features**, by the number of scenes short of the goal that they appear in (*whole*: "
                "how many of those would then open with nothing dropped):", "",
                "| feature | kind | scenes | whole | which |", "| --- | --- | --- | --- | --- |"]
        out += [f"| `{m.feature.replace('|', '/')}` | {m.kind} | {len(m.scenes)} | {len(m.sole_blocker)} | "
                f"{_md(', '.join(m.scenes))} |" for m in ranked]
    return "\n".join(out) + "\n"
