"""What LensLab's warnings on a scene say it left out, and which missing features they point to.

The importer and the renderer warn with one line per thing they approximate or leave out:
``file:line: <element type="..." id="...">: what is missing: what was done instead`` (several of these
joined by ``; `` when one element has several). ``lenslab validate --files`` sorts each part into

* **drops**: content that is not rendered as written: an element ignored or skipped, a light dropped, a
  texture or BSDF replaced by a placeholder colour. A scene with one of these does not meet the ``--files``
  goal (nothing dropped), whatever its image says;
* **approximates**: rendered differently but in substance (a filter, a clamp, a nearest rotation): the
  image's figures judge these;
* **notes**: the image is Mitsuba's all the same (Mitsuba ignores it too, a sampler mapped onto ours).

and names the missing **feature** each part points to: the element without its id and the first clause of
the part, numbers blanked, so that the same gap in many scenes counts once per scene (docs/validation.md,
"Mitsuba's own scenes"). The sorting reads the importer's wording: it is a heuristic, kept here in one place.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

DROPS, APPROXIMATES, NOTES = "drops", "approximates", "notes"

_WHERE = re.compile(r"^(?P<where>[^\n]+?(?::| line )\d+): ")  # file:line (a warning), file: line N (an error)
_LABEL = re.compile(r'^(?P<tag><[A-Za-z_]+)(?P<type> type="[^"]*")?(?: (?:id|name)="[^"]*")?>: ')
_NUMBER = re.compile(r"(?<![A-Za-z_])(?<!Mitsuba )[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")

# The image is the same as Mitsuba's: nothing to fix.
_NOTE_PATTERNS = [re.compile(p) for p in (
    r"Mitsuba 3 ignores it here too",
    r"adds nothing",
    r"kept, to match Mitsuba",
    r"is rendered with LensLab's .*sampler",
    r"only the first sensor is used",  # Mitsuba renders its first sensor too
    r"an invisible \(null BSDF\) shape without a light",  # invisible in Mitsuba as well
    r"-D \S+ is not used by the scene",
)]
# Content missing or replaced by a placeholder.
_DROP_PATTERNS = [re.compile(p) for p in (
    r"\bignored\b", r"\bskipped\b", r"\bdropped\b", r"\breplaces\b", r"lights nothing", r"\binstead\b",
    r"not readable", r"not renderable", r"untextured", r"stay visible", r"cannot be looked up",
    r"\b(grey|gray|white|mean colour)\b.* used", r"textures? (are|is) not supported", r"a textured \w+ is not supported",
    r"is not supported: a 45-degree camera",
)]


@dataclass(frozen=True)
class Finding:
    kind: str  # DROPS, APPROXIMATES or NOTES
    feature: str  # '<shape type="serialized">: Mitsuba .serialized meshes are not readable yet'
    text: str  # the part of the warning it comes from, without its file and line


def parts(warning: str) -> tuple[str, str, list[str]]:
    """(where, element, [what ...]) of one warning; where and element are "" when the line has none."""
    where, rest = "", warning.strip()
    m = _WHERE.match(rest)
    if m and not rest[m.end():].startswith(" "):
        where, rest = m.group("where"), rest[m.end():]
    element = ""
    m = _LABEL.match(rest)
    if m:
        element, rest = m.group("tag") + (m.group("type") or "") + ">", rest[m.end():]
    return where, element, [p.strip() for p in rest.split("; ") if p.strip()]


def classify(text: str) -> str:
    """DROPS, APPROXIMATES or NOTES for one part of a warning (see the module's doc)."""
    if any(p.search(text) for p in _NOTE_PATTERNS):
        return NOTES
    if any(p.search(text) for p in _DROP_PATTERNS):
        return DROPS
    return APPROXIMATES


def feature_name(element: str, text: str) -> str:
    cause = text.split(": ", 1)[0]
    cause = _NUMBER.sub("#", cause)
    return f"{element}: {cause}" if element else cause


def findings(warnings: list[str]) -> list[Finding]:
    """Each warning's parts, sorted and named; the same (kind, feature, text) once."""
    seen, out = set(), []
    for warning in warnings:
        _, element, texts = parts(warning)
        for text in texts:
            key = (classify(text), feature_name(element, text), text)
            if key not in seen:
                seen.add(key)
                out.append(Finding(*key))
    return out


def kind_of(warning: str) -> str:
    """The gravest kind among one warning's parts."""
    kinds = {f.kind for f in findings([warning])}
    return next((k for k in (DROPS, APPROXIMATES) if k in kinds), NOTES)


def drops(warnings: list[str]) -> list[Finding]:
    return [f for f in findings(warnings) if f.kind == DROPS]


@dataclass(frozen=True)
class MissingFeature:
    feature: str
    kind: str
    scenes: tuple[str, ...]  # the failing scenes whose warnings point to it
    sole_blocker: tuple[str, ...]  # those whose only dropping feature it is: they would open whole with it


def rank_missing_features(failing: dict[str, list[str]], refused: dict[str, str] | None = None) -> list[MissingFeature]:
    """The features that LensLab's warnings on the failing scenes (name -> warnings) point to, most scenes first
    (the drops before the approximations at equal counts). ``refused``: name -> the error with which LensLab
    would not open a scene that Mitsuba renders: what it names is missing too, and drops the whole scene."""
    by_feature: dict[tuple[str, str], list[str]] = {}
    dropping: dict[str, set[str]] = {}
    for name, warnings in failing.items():
        found = findings(warnings)
        if refused and name in refused:
            _, element, texts = parts(refused[name])
            found += [Finding(DROPS, feature_name(element, texts[0] if texts else ""), refused[name])]
        for f in found:
            if f.kind == NOTES:
                continue
            scenes = by_feature.setdefault((f.feature, f.kind), [])
            if name not in scenes:
                scenes.append(name)
            if f.kind == DROPS:
                dropping.setdefault(name, set()).add(f.feature)
    ranked = []
    for (feature, kind), scenes in by_feature.items():
        sole = tuple(n for n in scenes if kind == DROPS and dropping.get(n) == {feature})
        ranked.append(MissingFeature(feature, kind, tuple(scenes), sole))
    order = {DROPS: 0, APPROXIMATES: 1}
    ranked.sort(key=lambda m: (-len(m.scenes), order[m.kind], -len(m.sole_blocker), m.feature))
    return ranked


def count_kinds(warnings: list[str]) -> Counter:
    return Counter(f.kind for f in findings(warnings))
