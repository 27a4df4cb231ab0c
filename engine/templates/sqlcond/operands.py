"""Operand checks shared by the runtime helpers: SQL kinds, limits, deferred operands."""

from __future__ import annotations

import numbers
from decimal import Decimal

from ..guards import short_repr

MAX_TEXT_LENGTH = 1 << 16  # characters of a string built by ||
MAX_INT_BITS = 4_096  # bits of an integer built by + - *

_KINDS = {bool: "boolean", int: "number", float: "number", Decimal: "number", str: "text"}


def _kind(value):
    kind = _KINDS.get(type(value))
    if kind is not None:
        return kind
    if isinstance(value, numbers.Number):
        return "number"
    if isinstance(value, str):
        return "text"
    return type(value).__name__


def _describe(value):
    """A value in a message: never the whole of a large one."""
    return f"{_kind(value)} {short_repr(value)}"


def _same_number_type(a, b):
    """Mixed Decimal/float operands are compared and combined as floats."""
    if type(a) is not type(b) and (isinstance(a, float) or isinstance(b, float)):
        return float(a), float(b)
    return a, b


def _comparable(a, b, op):
    kind_a, kind_b = _kind(a), _kind(b)
    if kind_a != kind_b:
        raise TypeError(f"cannot compare {_describe(a)} with {_describe(b)} using {op}")
    if kind_a == "number":
        return _same_number_type(a, b)
    return a, b


def _numbers(a, b, op):
    if _kind(a) != "number":
        raise TypeError(f"operator {op} needs numbers, got {_describe(a)}")
    if _kind(b) != "number":
        raise TypeError(f"operator {op} needs numbers, got {_describe(b)}")
    return _same_number_type(a, b)


def _number(value, name):
    if _kind(value) != "number":
        raise TypeError(f"{name} needs a number, got {_describe(value)}")
    return value


class _Deferred:
    """An operand that is evaluated only when a lazy helper asks for it."""

    __slots__ = ("fn", "args", "strict")

    def __init__(self, fn, args, strict):
        self.fn = fn
        self.args = args
        self.strict = strict

    def force(self):
        if self.strict:
            return self.fn(*[_force(arg) for arg in self.args])
        return self.fn(*self.args)


def _force(value):
    return value.force() if type(value) is _Deferred else value


def _boolean(value, op):
    value = _force(value)
    if value is None or value is True or value is False:
        return value
    raise TypeError(f"argument of {op} must be boolean, got {_describe(value)}")
