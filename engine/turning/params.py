"""Reading a turning job's stored parameters (JSON edited in SQL): each reader returns the
value with its JSON type checked, or an error naming the parameter and what to do."""
from __future__ import annotations

import math
from typing import Any

from ..errors import EngineError

FIX = "set it in SQL (job.params / job.module_params) and instantiate the job again"


def number_param(values: dict, key: str, where: str, minimum: float | None = None,
                 above: bool = False) -> float:
    """A number from stored parameters (at least, or above, `minimum`), or an error naming it."""
    value: Any = values.get(key)
    wrong = isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value)
    if not wrong and minimum is not None:
        wrong = value <= minimum if above else value < minimum
    if wrong:
        rule = "a number" if minimum is None else f"a number {'above' if above else 'of at least'} {minimum:g}"
        raise EngineError(f"{where}.{key} = {value!r} must be {rule}; {FIX}")
    return float(value)


def integer_param(values: dict, name: str, where: str, low: int, high: int) -> int:
    value = values.get(name)
    if type(value) is not int or not low <= value <= high:
        raise EngineError(f"{where}.{name} = {value!r} must be a whole number {low} … {high}; {FIX}")
    return value


def bool_param(values: dict, name: str, where: str) -> bool:
    """true or false as JSON: a string "false" would read as true."""
    value = values.get(name)
    if type(value) is not bool:
        raise EngineError(f"{where}.{name} = {value!r} must be true or false (JSON, not a string); {FIX}")
    return value
