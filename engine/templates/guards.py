"""Bounds on what a template expression may build (asteval's own guards and limits, applied to
compiled code): the operators that can allocate without bound, str() and round(), and the width
and precision of a format spec. nc_path checks its formats with the same check_format_spec."""
from __future__ import annotations

import re

MAX_STRING_LENGTH = 1 << 16        # characters of any string an expression builds
MAX_INT_BITS = 4_096               # bits of any integer an expression builds
MAX_FORMAT_WIDTH = 200             # width/precision in a format spec


def _bits(value) -> int:
    return value.bit_length() if isinstance(value, int) else 0


def _too_long(value) -> bool:
    return isinstance(value, (str, bytes, tuple, list)) and len(value) > MAX_STRING_LENGTH


def guard_length(result):
    if _too_long(result):
        raise ValueError(f"result longer than {MAX_STRING_LENGTH} characters")
    return result


def safe_pow(base, exponent):
    if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1:
        if exponent * abs(base).bit_length() > MAX_INT_BITS:
            raise ValueError(f"power too large (more than {MAX_INT_BITS} bits)")
    return base ** exponent


def safe_mult(left, right):
    if isinstance(left, int) and isinstance(right, int):
        if _bits(left) + _bits(right) > MAX_INT_BITS:
            raise ValueError(f"product too large (more than {MAX_INT_BITS} bits)")
    for sequence, count in ((left, right), (right, left)):
        if isinstance(sequence, (str, tuple, list)) and isinstance(count, int):
            if len(sequence) * count > MAX_STRING_LENGTH:
                raise ValueError(f"repetition longer than {MAX_STRING_LENGTH} characters")
    return left * right


def safe_add(left, right):
    if isinstance(left, (str, tuple, list)) and isinstance(right, type(left)):
        if len(left) + len(right) > MAX_STRING_LENGTH:
            raise ValueError(f"result longer than {MAX_STRING_LENGTH} characters")
    return left + right


def safe_lshift(left, right):
    if isinstance(right, int) and right + _bits(left) > MAX_INT_BITS:
        raise ValueError(f"shift too large (more than {MAX_INT_BITS} bits)")
    return left << right


def safe_mod(left, right):
    if isinstance(left, str):
        raise ValueError("'%' string formatting is not allowed; use an f-string")
    return left % right


_FORMAT_NUMBERS = re.compile(r"\d+")


def check_format_spec(spec: str) -> None:
    if any(int(number) > MAX_FORMAT_WIDTH for number in _FORMAT_NUMBERS.findall(spec)):
        raise ValueError(f"format width or precision above {MAX_FORMAT_WIDTH} in {spec!r}")


def safe_format(value, spec: str) -> str:
    """format() with the width and precision of the spec bounded."""
    check_format_spec(spec)
    return format(value, spec)


def safe_str(value=""):
    if isinstance(value, int) and _bits(value) > MAX_INT_BITS:
        raise ValueError("integer too large to print")
    return guard_length(str(value))


def safe_round(value, digits=None):
    if digits is not None and abs(digits) > MAX_FORMAT_WIDTH:
        raise ValueError(f"round() to more than {MAX_FORMAT_WIDTH} digits")
    return round(value) if digits is None else round(value, digits)
