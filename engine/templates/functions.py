"""The table of functions and constants a template expression may name: math, bounded
builtins and nc_path. The whitelist checks calls against it; evaluation runs with it."""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from .guards import safe_format, safe_int, safe_round, safe_str
from .nc_path import nc_path

_MATH = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "radians", "degrees", "sqrt",
         "hypot", "ceil", "floor", "trunc", "fabs", "copysign", "exp", "log", "log10", "isclose")
FUNCTIONS: dict[str, Callable[..., Any]] = {name: getattr(math, name) for name in _MATH}
FUNCTIONS.update({
    "abs": abs, "min": min, "max": max, "round": safe_round, "int": safe_int, "float": float,
    "str": safe_str, "bool": bool, "len": len, "format": safe_format,
})
FUNCTIONS["nc_path"] = nc_path   # a tool path, one NC block per move (engine.templates.nc_path)
NC_NUMBER_SPEC = "~"   # `{feed:~#.000}`: the f-string field of an imported word (engine.templates.evaluator)


def nc_number(value, style: str) -> str:
    """engine.templates.nc_number.written_number, loaded at the first imported word a template prints:
    a template written by hand prints none (issue 28: a start-up imports what it uses)."""
    from .nc_number import written_number

    return written_number(value, style)


FUNCTIONS["nc_number"] = nc_number   # a bound word of an imported program, exactly (engine.templates.nc_number)
CONSTANTS = {"pi": math.pi, "e": math.e, "True": True, "False": False, "None": None}
