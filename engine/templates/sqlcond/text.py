"""Text helpers: LIKE, ILIKE and || (concatenation)."""

from __future__ import annotations

import functools
import re
from decimal import Decimal

from ..budget import paid
from .operands import MAX_TEXT_LENGTH, _describe

MAX_PATTERN_LENGTH = 1_000   # characters of a LIKE pattern (a template's patterns are a few words)
MAX_LIKE_STEPS = 1 << 22     # text length times pattern length: what one match may cost (a few ms)


class _LikePattern:
    """A LIKE pattern split at its ``%`` wildcards into fixed-length segments.

    Matching the first segment at the start, the last at the end and each middle
    segment at its leftmost position in between is exact for such patterns and
    takes O(len(value) * len(pattern)), unlike one backtracking regex with
    several ``.*`` (which can take exponential time).
    """

    __slots__ = ("whole", "first", "middle", "last", "last_length")

    def __init__(self, segments, flags):
        compiled = [re.compile("".join(parts), flags | re.DOTALL) for parts in segments]
        self.whole = len(compiled) == 1  # no % at all
        self.first, self.middle, self.last = compiled[0], compiled[1:-1], compiled[-1]
        self.last_length = len(segments[-1])

    def matches(self, value):
        if self.whole:
            return self.first.fullmatch(value) is not None
        found = self.first.match(value)
        if found is None:
            return False
        position, tail = found.end(), len(value) - self.last_length
        for segment in self.middle:
            found = segment.search(value, position, tail)
            if found is None:
                return False
            position = found.end()
        return position <= tail and self.last.fullmatch(value, tail) is not None


@functools.lru_cache(maxsize=512)
def _like_pattern(pattern, escape, flags):
    if len(escape) > 1:
        raise ValueError(f"invalid escape string {escape!r}: use one character or ''")
    segments: list[list[str]] = [[]]  # each segment: regex parts, one per character matched
    chars = iter(pattern)
    for char in chars:
        if escape and char == escape:
            literal = next(chars, None)
            if literal is None:
                raise ValueError("LIKE pattern must not end with escape character")
            segments[-1].append(re.escape(literal))
        elif char == "%":
            segments.append([])
        elif char == "_":
            segments[-1].append(".")
        else:
            segments[-1].append(re.escape(char))
    return _LikePattern(segments, flags)


def _like(value, pattern, escape, flags, op):
    if value is None or pattern is None or escape is None:
        return None
    for operand in (value, pattern, escape):
        if not isinstance(operand, str):
            raise TypeError(f"operator {op} needs text, got {_describe(operand)}")
    if len(pattern) > MAX_PATTERN_LENGTH:   # matching costs the pattern's length times the text's
        raise ValueError(f"{op} pattern longer than {MAX_PATTERN_LENGTH} characters")
    if len(value) * len(pattern) > MAX_LIKE_STEPS:   # one regex search cannot be stopped at the deadline
        raise ValueError(f"{op} of a text of {len(value)} characters with a pattern of {len(pattern)}: "
                         f"more than {MAX_LIKE_STEPS} steps")
    return _like_pattern(pattern, escape, flags).matches(value)


def _sql_like(value, pattern, escape="\\"):
    return _like(value, pattern, escape, 0, "LIKE")


def _sql_ilike(value, pattern, escape="\\"):
    return _like(value, pattern, escape, re.IGNORECASE, "ILIKE")


def _text(value):
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if not isinstance(value, (int, float, Decimal)):
        raise TypeError(f"operator || joins text and numbers, not {_describe(value)}")
    return str(value)


def _sql_concat(a, b):
    if a is None or b is None:
        return None
    if not isinstance(a, str) and not isinstance(b, str):
        raise TypeError(f"operator || needs a text operand, got {_describe(a)} and {_describe(b)}")
    text = _text(a) + _text(b)
    if len(text) > MAX_TEXT_LENGTH:
        raise ValueError(f"string too long (more than {MAX_TEXT_LENGTH} characters)")
    return paid(text)
