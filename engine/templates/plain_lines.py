"""The gate's verdict on the two shapes most rows have, read off the shape (engine.templates.
expressions): a text written out (`"G0 Z5."`) and an f-string of written text and plain fields
(`f"G1 X{x_cut:.3f} F{feed}"`: a parameter's name, a fixed format spec). An imported program is
thousands of such lines; the full gate takes five times as long to say the same. Anything else,
and anything the full gate would refuse, is left to the full gate (None).

For these shapes the full gate finds: every node allowed, no call, no part without parameters,
and one guard, `_guard(...)` around the f-string; the fields' names are the names read (those of
CONSTANTS excepted). tests/test_expressions.py checks that both give the same tree."""
from __future__ import annotations

import ast

from .functions import CONSTANTS, FUNCTIONS
from .guards import MAX_INT_BITS, check_format_spec


def plain(body: ast.expr, max_nodes: int) -> tuple[ast.expr, frozenset] | None:
    """(guarded body, names read) of a plain line, else None."""
    if type(body) is ast.Constant:
        return _written(body)
    if type(body) is not ast.JoinedStr:
        return None
    names, nodes = [], 2   # the Expression and the JoinedStr, counted as the full gate counts
    for value in body.values:
        if type(value) is ast.Constant and type(value.value) is str:
            nodes += 1
        elif type(value) is ast.FormattedValue and _plain_field(value):
            name, spec = value.value, value.format_spec
            assert isinstance(name, ast.Name) and (spec is None or isinstance(spec, ast.JoinedStr))   # a plain field
            names.append(name.id)
            nodes += 3 + (0 if spec is None else 1 + len(spec.values))
        else:
            return None
    if nodes > max_nodes:
        return None
    guarded = ast.copy_location(ast.Call(ast.Name("_guard", ast.Load()), [body], []), body)
    return guarded, frozenset(name for name in names if name not in CONSTANTS)


def _written(body: ast.Constant) -> tuple[ast.expr, frozenset] | None:
    value = body.value
    if type(value) is str or type(value) is float or type(value) is int and value.bit_length() <= MAX_INT_BITS:
        return body, frozenset()
    return None


def _plain_field(field: ast.FormattedValue) -> bool:
    """`{name}` or `{name:spec}`: a name the gate allows as a value, no conversion, a fixed spec
    within the width the guards allow."""
    name = field.value
    if type(name) is not ast.Name or name.id.startswith("_") or name.id in FUNCTIONS or field.conversion != -1:
        return False
    spec = field.format_spec
    if spec is None:
        return True
    if type(spec) is not ast.JoinedStr or not all(type(part) is ast.Constant for part in spec.values):
        return False
    try:
        check_format_spec("".join(part.value for part in spec.values
                                  if isinstance(part, ast.Constant) and isinstance(part.value, str)))
    except ValueError:
        return False
    return True
