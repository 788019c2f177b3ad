"""What a field of a scene class accepts, read from where the field is declared.

Scene classes declare each field's range or choices once, in the dataclass field's metadata
(``field(default=2.8, metadata={"range": F_NUMBER_RANGE})``). Everything that checks or offers a value asks
here: the scene-file reader, the command line's arguments, the studio's number fields, overrides.
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
