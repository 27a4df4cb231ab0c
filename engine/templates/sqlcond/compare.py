"""Comparison helpers: =, <>, <, <=, >, >=, IS tests, BETWEEN, IN, LEAST, GREATEST, NULLIF.

A NULL operand makes a comparison NULL.  Text never equals a number and a boolean
never equals a number (FALSE); ordering comparisons between different kinds raise
TypeError.
"""

from __future__ import annotations

from .logic import _sql_and, _sql_or
from .operands import _comparable, _kind, _same_number_type


def _sql_eq(a, b):
    if a is None or b is None:
        return None
    kind = _kind(a)
    if kind != _kind(b):
        return False
    if kind == "number":
        a, b = _same_number_type(a, b)
    return a == b


def _sql_ne(a, b):
    result = _sql_eq(a, b)
    return None if result is None else not result


def _sql_lt(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, "<")
    return a < b


def _sql_le(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, "<=")
    return a <= b


def _sql_gt(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, ">")
    return a > b


def _sql_ge(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, ">=")
    return a >= b


def _sql_is_null(value):
    return value is None


def _sql_is_true(value):
    return value is True


def _sql_is_false(value):
    return value is False


def _sql_distinct(a, b):
    """a IS DISTINCT FROM b: like <>, but NULL is a comparable value."""
    if a is None or b is None:
        return (a is None) is not (b is None)
    return not _sql_eq(a, b)


def _sql_not_distinct(a, b):
    return not _sql_distinct(a, b)


def _sql_between(value, low, high):
    return _sql_and(_sql_ge(value, low), _sql_le(value, high))


def _sql_between_symmetric(value, low, high):
    return _sql_or(_sql_between(value, low, high), _sql_between(value, high, low))


def _sql_in(value, *items):
    if value is None:
        return None
    result: bool | None = False
    for item in items:
        equal = _sql_eq(value, item)
        if equal:
            return True
        if equal is None:
            result = None
    return result


def _sql_least(*args):
    best = None
    for value in args:
        if value is not None and (best is None or _sql_lt(value, best)):
            best = value
    return best


def _sql_greatest(*args):
    best = None
    for value in args:
        if value is not None and (best is None or _sql_gt(value, best)):
            best = value
    return best


def _sql_nullif(a, b):
    return None if _sql_eq(a, b) is True else a
