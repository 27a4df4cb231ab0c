"""The gate's verdict on the two shapes most rows have, read off the shape (engine.templates.
expressions): a text written out (`"G0 Z5."`) and an f-string of written text and plain fields
(`f"G1 X{x_cut:.3f} F{feed}"`: a parameter's name, a fixed format spec; or an imported number,
`{nc_number(feed, '0.010')}`: engine.templates.nc_number). An imported program is
thousands of such lines; the full gate takes five times as long to say the same. Anything else,
and anything the full gate would refuse, is left to the full gate (None).

For these shapes the full gate finds: every node allowed, no call, no part without parameters,
and one guard, `_guard(...)` around the f-string; the fields' names are the names read (those of
CONSTANTS excepted), and nc_number the one function called. tests/test_expressions.py checks that
both give the same tree."""
from __future__ import annotations

import ast

from .functions import CONSTANTS, FUNCTIONS
from .guards import MAX_INT_BITS, check_format_spec


def plain(body: ast.expr, max_nodes: int) -> tuple[ast.expr, frozenset, frozenset] | None:
    """(guarded body, names read, functions called) of a plain line, else None."""
    if type(body) is ast.Constant:
        return _written(body)
    if type(body) is not ast.JoinedStr:
        return None
    names, nodes, calls = [], 2, set()   # the Expression and the JoinedStr, counted as the full gate counts
    for value in body.values:
        if type(value) is ast.Constant and type(value.value) is str:
            nodes += 1
        elif type(value) is ast.FormattedValue and _number_field(value):
            call = value.value
            assert isinstance(call, ast.Call) and isinstance(call.args[0], ast.Name)
            names.append(call.args[0].id)
            calls.add(NC_NUMBER)
            nodes += 7   # FormattedValue, Call, the function's Name and Load, the Name and Load, the style
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
    return guarded, frozenset(name for name in names if name not in CONSTANTS), frozenset(calls)


def _written(body: ast.Constant) -> tuple[ast.expr, frozenset, frozenset] | None:
    value = body.value
    if type(value) is str or type(value) is float or type(value) is int and value.bit_length() <= MAX_INT_BITS:
        return body, frozenset(), frozenset()
    return None


NC_NUMBER = "nc_number"


def _number_field(field: ast.FormattedValue) -> bool:
    """`{nc_number(name, 'style')}`: an imported number, a parameter's name and a text, nothing more."""
    call = field.value
    if type(call) is not ast.Call or field.conversion != -1 or field.format_spec is not None or call.keywords:
        return False
    function, arguments = call.func, call.args
    return (type(function) is ast.Name and function.id == NC_NUMBER and len(arguments) == 2
            and type(arguments[0]) is ast.Name and not arguments[0].id.startswith("_")
            and arguments[0].id not in FUNCTIONS and arguments[0].id not in CONSTANTS
            and type(arguments[1]) is ast.Constant and type(arguments[1].value) is str)


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
