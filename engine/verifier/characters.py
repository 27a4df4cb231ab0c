"""Every emitted line holds printable ASCII only, comments and headers included. A line break,
carriage return or NUL inside a line (from a program name, a drawing name or a template row)
would turn one line into several blocks on the control, none of which the verifier read."""
from __future__ import annotations

import re

from .refusals import Refused

PRINTABLE_ASCII = re.compile(r"[ -~]*")
CHARACTER_NAMES = {"\n": "a line feed (LF)", "\r": "a carriage return (CR)", "\x00": "a NUL",
                   "\t": "a tab", "\x7f": "a DEL", "\x0c": "a form feed", "\x0b": "a vertical tab"}


def check_characters(line: object) -> None:
    if not isinstance(line, str):
        raise Refused(f"a line must be text, not {type(line).__name__}")
    if PRINTABLE_ASCII.fullmatch(line):
        return
    column, character = next((i, c) for i, c in enumerate(line, start=1) if not " " <= c <= "~")
    raise Refused(f"{_named(character)} at column {column}: an emitted line holds printable ASCII only, "
                  "or the control would read blocks nobody checked")


def check_comment_characters(text: str, column_from: int = 1) -> None:
    """A comment of a program as stored on the control may hold any printable text (umlauts: issue
    27), never a control, format or line-separating character, which would break the line."""
    for column, character in enumerate(text, start=column_from):
        if not (character.isprintable() or character == " "):
            raise Refused(f"{_named(character)} at column {column}: a line holds no control character, "
                          "or the control would read blocks nobody checked")


def _named(character: str) -> str:
    if character in CHARACTER_NAMES:
        return CHARACTER_NAMES[character]
    kind = "a control character" if ord(character) < 0x20 or 0x7f <= ord(character) < 0xa0 else "a non-ASCII character"
    return f"{kind} U+{ord(character):04X}"
