"""Messages a terminal can trust: one line, nothing in it that a terminal would obey, nothing endless.

Error and warning lines quote what users and files wrote (a material's name, a value, a path), and a file
can hold anything: an escape sequence that clears the screen, a newline that forges a second message, a
100 KB string. Every line LensLab prints on stderr goes through :func:`one_line`; the studio's dialogs use it
too, so that a message reads the same everywhere.
"""

from __future__ import annotations

import re

#: C0 and C1 control characters, DEL, and the Unicode controls that reorder or hide text.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u200b-\u200f\u202a-\u202e\u2066-\u2069]")
#: A run of text without spaces longer than this (a pasted value, a path of a hundred folders) is shortened
#: in its middle; a real path of a few folders stays whole.
LONGEST_WORD = 240
#: And the whole line, whatever it holds.
LONGEST_LINE = 1000


def _escape(match: re.Match) -> str:
    char = match.group()
    return {"\n": "\\n", "\r": "\\r", "\t": " "}.get(char, f"\\x{ord(char):02x}" if ord(char) < 0x100
                                                      else f"\\u{ord(char):04x}")


def shorten(text: str, limit: int) -> str:
    """``text`` with its middle replaced by '…' if it is longer than ``limit`` characters."""
    if len(text) <= limit:
        return text
    head = (limit - 1) * 2 // 3
    tail = limit - 1 - head
    return text[:head] + "…" + text[-tail:]


def one_line(text: object, prefix: str = "") -> str:
    """``prefix`` and ``text`` as one printable line of at most LONGEST_LINE characters: control characters
    written as escapes (ESC as \\x1b), overlong words and the text itself shortened in the middle."""
    line = _CONTROL.sub(_escape, str(text))
    # A lone surrogate (JSON's "\ud800") cannot be written in UTF-8 at all: written as its escape.
    line = line.encode("utf-8", "backslashreplace").decode("utf-8")
    words = [shorten(word, LONGEST_WORD) for word in line.split(" ")]
    return prefix + shorten(" ".join(words), LONGEST_LINE - len(prefix))


def describe_os_error(exc: OSError) -> str:
    """``path: what went wrong`` for an error of the operating system: Python's own text ("[Errno 36] File
    name too long: '...'") puts the file last, in quotes, and the errno first."""
    if exc.filename is None or not exc.strerror:
        return str(exc)
    text = f"{exc.filename}: {exc.strerror}"
    return text if exc.filename2 is None else f"{text} ({exc.filename2})"
