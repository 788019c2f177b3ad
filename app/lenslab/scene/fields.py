"""What a field of a scene class accepts, read from where the field is declared.

Scene classes declare each field's range or choices once, in the dataclass field's metadata
(``field(default=2.8, metadata={"range": F_NUMBER_RANGE})``). Everything that checks or offers a value asks
here: the scene-file reader, the command line's arguments, the studio's number fields, overrides.

Two ranges, where they differ. ``"range"`` is what a value may *be*: what the scene-file reader, importers, the
command line and batch files accept (:func:`declared_range`). ``"controls"`` is what the studio's sliders, spin
boxes and presets *offer* (:func:`control_range`; the declared range where a field names none): f/0.5 to f/128
for an f-number that may be f/0.13. A control range limits what the controls offer, never what a scene holds: a
control showing a value outside it shows it as it is (:func:`range_holding`) and leaves it so.

A text field whose values no fixed list holds (a texture's ``color_space``: a keyword or any colour space of the
OCIO config) names a ``"check"`` instead of ``"choices"``: a function of the value that says what is wrong with it
in words, or None; ``"suggestions"`` are the values a control may offer while still taking any other
(:func:`text_problem`).
"""

from __future__ import annotations

import dataclasses


def _metadata(cls: type, field_name: str):
    fields = {f.name: f for f in dataclasses.fields(cls)}
    if field_name not in fields:
        raise KeyError(f"{cls.__name__} has no field '{field_name}'")
    return fields[field_name].metadata


def declared_range(cls: type, field_name: str) -> tuple:
    """(low, high), both accepted, of a numeric field of ``cls``."""
    return tuple(_metadata(cls, field_name)["range"])


def declared_choices(cls: type, field_name: str) -> tuple[str, ...]:
    """The values a text field of ``cls`` may take."""
    return tuple(_metadata(cls, field_name)["choices"])


def text_problem(metadata, value: str) -> str | None:
    """Why a text field with this metadata does not take ``value``: not one of its ``"choices"``, or what its
    ``"check"`` says; None when it takes it."""
    if "choices" in metadata and value not in metadata["choices"]:
        return f"'{value}' is not one of {', '.join(metadata['choices'])}"
    if "check" in metadata:
        return metadata["check"](value)
    return None


def control_range(cls: type, field_name: str) -> tuple:
    """(low, high) the studio's controls offer for a numeric field of ``cls``: its ``"controls"`` metadata, else
    its declared range."""
    return control_bounds(_metadata(cls, field_name))


def control_bounds(metadata, default: tuple | None = None) -> tuple:
    """(low, high) a control offers for a field with this metadata: its ``"controls"``, else its ``"range"``, else
    ``default``."""
    return tuple(metadata.get("controls", metadata.get("range", default)))


def range_holding(low: float, high: float, value: float) -> tuple[float, float]:
    """A control's range widened just enough to hold ``value`` (a scene's value beyond what the control offers
    is shown as it is, not clamped into the control's range)."""
    return min(low, value), max(high, value)
