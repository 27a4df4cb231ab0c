"""Three-valued logic and the lazy helpers (AND, OR, NOT, CASE, COALESCE).

AND, OR, CASE and COALESCE take operands after the first as thunks (``_Deferred``)
and force them only while the result is still open, as PostgreSQL does in practice.
"""

from __future__ import annotations

from .operands import _boolean, _force


def _sql_truth(value):
    """Final verdict of a condition: only TRUE counts, NULL is false."""
    return value is True


def _sql_and(*args):
    result: bool | None = True
    for arg in args:
        value = _boolean(arg, "AND")
        if value is False:
            return False
        if value is None:
            result = None
    return result


def _sql_or(*args):
    result: bool | None = False
    for arg in args:
        value = _boolean(arg, "OR")
        if value is True:
            return True
        if value is None:
            result = None
    return result


def _sql_not(value):
    value = _boolean(value, "NOT")
    return None if value is None else not value


def _sql_coalesce(*args):
    for arg in args:
        value = _force(arg)
        if value is not None:
            return value
    return None


def _sql_case(*args):
    """Arguments: condition, result, condition, result, ..., else-result."""
    last = len(args) - 1
    for index in range(0, last, 2):
        if _boolean(args[index], "CASE WHEN") is True:
            return _force(args[index + 1])
    return _force(args[last])
