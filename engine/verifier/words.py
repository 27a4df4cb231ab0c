"""The value of each address word, read by its kind (engine.verifier.grammar) and
checked where the check needs no machine: S, F and a thread's pitch above 0, F at most about a
rapid traverse, tool and offset numbers in range, an arc radius not 0, a swivel within a turn.
The machine's own limits (travel, spindle maximum) are engine.verifier.limits."""
from __future__ import annotations

import re

from ..nc.words import MAX_TOOL
from .grammar import (
    ANGLE,
    CODE,
    FEED,
    OFFSET,
    PITCH,
    POSITION,
    RADIUS,
    SPEED,
    SPEED_LIMIT,
    SPINDLE_POSITION,
    TOOL,
    TOOL_AND_OFFSET,
    TOOL_OR_NAME,
)
from .numbers import digits, plain_decimal
from .refusals import Refused

MAX_FEED = 20000.0    # mm/min: about a rapid traverse; a larger F is a unit slip or a typo
MAX_ANGLE = 360.0     # degrees: a swivel beyond a whole turn is a unit slip
TOOL_NAME = re.compile(r'"[A-Za-z0-9_.\-]{1,32}"')


def _code(word: str, text: str) -> int:
    return digits(word, text, range(1, 4), f"a {word} code")


def _position(word: str, text: str) -> float:
    return plain_decimal(word, text)


def _above_zero(word: str, text: str) -> float:
    value = plain_decimal(word, text)
    if value <= 0:
        raise Refused(f"{word}{text} must be above 0")
    return value


def _feed(word: str, text: str) -> float:
    value = _above_zero(word, text)
    if value > MAX_FEED:
        raise Refused(f"feed {word}{text} exceeds {MAX_FEED:g} (mm/min), more than a rapid traverse")
    return value


def _angle(word: str, text: str) -> float:
    value = plain_decimal(word, text)
    if abs(value) > MAX_ANGLE:
        raise Refused(f"{word}{text}: a swivel beyond ±{MAX_ANGLE:g}° is a unit slip")
    return value


def _radius(word: str, text: str) -> float:
    value = plain_decimal(word, text)
    if value == 0:
        raise Refused(f"arc radius {word}{text} must not be 0")
    return value


def _tool(word: str, text: str) -> int:
    number = digits(word, text, range(1, 3), f"a tool 1 … {MAX_TOOL}")
    if number < 1:
        raise Refused(f"tool {word}{text} is not 1 … {MAX_TOOL}")
    return number


def _tool_and_offset(word: str, text: str) -> int:
    number = digits(word, text, range(4, 5), f"T<tool><offset>, two digits each, tool 01 … {MAX_TOOL}")
    if number // 100 < 1:
        raise Refused(f"{word}{text} is not T<tool><offset>, two digits each, tool 01 … {MAX_TOOL}")
    return number


def _tool_or_name(word: str, text: str) -> int:
    """840D lathe: T<n>, or T="<name>" (the tool list's name; letters, digits, _ . -): a name is
    tool 0 here, the change is what the verifier follows."""
    if word == "T=" and TOOL_NAME.fullmatch(text):
        return 0
    return _tool(word, text)


def _offset(word: str, text: str) -> int:
    return digits(word, text, range(1, 3), f"a tool offset 0 … {MAX_TOOL}")


READERS = {CODE: _code, POSITION: _position, ANGLE: _angle, FEED: _feed, SPEED: _above_zero,
           PITCH: _above_zero, RADIUS: _radius, TOOL: _tool, TOOL_AND_OFFSET: _tool_and_offset,
           OFFSET: _offset, SPINDLE_POSITION: _angle, SPEED_LIMIT: _above_zero, TOOL_OR_NAME: _tool_or_name}
