"""Arithmetic helpers: + - * / % ^, unary -, ABS, SQRT, FLOOR, CEIL, ROUND.

Booleans are not numbers.  ``/`` on two integers truncates toward zero and ``%``
takes the sign of the dividend, as in PostgreSQL.
"""

from __future__ import annotations

import math
from decimal import ROUND_CEILING, ROUND_FLOOR, ROUND_HALF_UP, Context, Decimal

from .operands import MAX_INT_BITS, _describe, _number, _numbers


def _bounded(number):
    if type(number) is int and number.bit_length() > MAX_INT_BITS:
        raise OverflowError(f"integer out of range (more than {MAX_INT_BITS} bits)")
    return number


def _sql_neg(value):
    if value is None:
        return None
    return -_number(value, "unary -")


def _sql_add(a, b):
    if a is None or b is None:
        return None
    a, b = _numbers(a, b, "+")
    return _bounded(a + b)


def _sql_sub(a, b):
    if a is None or b is None:
        return None
    a, b = _numbers(a, b, "-")
    return _bounded(a - b)


def _sql_mul(a, b):
    if a is None or b is None:
        return None
    a, b = _numbers(a, b, "*")
    return _bounded(a * b)


def _sql_div(a, b):
    if a is None or b is None:
        return None
    a, b = _numbers(a, b, "/")
    if b == 0:
        raise ZeroDivisionError("division by zero")
    if isinstance(a, int) and isinstance(b, int):
        quotient = abs(a) // abs(b)
        return -quotient if (a < 0) != (b < 0) else quotient
    return a / b


def _sql_mod(a, b):
    if a is None or b is None:
        return None
    a, b = _numbers(a, b, "%")
    if b == 0:
        raise ZeroDivisionError("division by zero")
    if isinstance(a, int) and isinstance(b, int):
        remainder = abs(a) % abs(b)
        return -remainder if a < 0 else remainder
    if isinstance(a, float) or isinstance(b, float):
        return math.fmod(a, b)
    return a % b  # Decimal: sign of the dividend already


def _sql_power(a, b):
    if a is None or b is None:
        return None
    base, exponent = (float(x) for x in _numbers(a, b, "^"))
    if base == 0 and exponent < 0:
        raise ZeroDivisionError("zero raised to a negative power is undefined")
    if base < 0 and not exponent.is_integer():
        raise ValueError("a negative number raised to a non-integer power yields a complex result")
    try:
        return math.pow(base, exponent)
    except OverflowError:
        raise OverflowError("value out of range: overflow") from None


def _sql_abs(value):
    if value is None:
        return None
    return abs(_number(value, "ABS"))


def _sql_sqrt(value):
    if value is None:
        return None
    if _number(value, "SQRT") < 0:
        raise ValueError("cannot take square root of a negative number")
    return value.sqrt() if isinstance(value, Decimal) else math.sqrt(value)


def _integral(value, name, rounding, float_fn):
    if value is None:
        return None
    _number(value, name)
    if isinstance(value, int):
        return value
    if isinstance(value, Decimal):
        return value.to_integral_value(rounding=rounding)
    value = float(value)
    return float(float_fn(value)) if math.isfinite(value) else value


def _sql_floor(value):
    return _integral(value, "FLOOR", ROUND_FLOOR, math.floor)


def _sql_ceil(value):
    return _integral(value, "CEIL", ROUND_CEILING, math.ceil)


_ROUND_CONTEXT = Context(prec=1000)


def _sql_round(value, digits=0):
    """Round half away from zero (like PostgreSQL's numeric), keeping the argument's type."""
    if value is None or digits is None:
        return None
    _number(value, "ROUND")
    if not isinstance(digits, int) or isinstance(digits, bool):
        raise TypeError(f"ROUND needs an integer number of digits, got {_describe(digits)}")
    if isinstance(value, int) and digits >= 0:
        return value
    if isinstance(value, float) and not math.isfinite(value):
        return value
    exact = value if isinstance(value, Decimal) else Decimal(repr(value))
    if _exponent(exact) >= -digits:
        return value  # nothing to round away
    rounded = exact.quantize(Decimal(1).scaleb(-digits), ROUND_HALF_UP, _ROUND_CONTEXT)
    return type(value)(rounded) if isinstance(value, (int, float)) else rounded


def _exponent(number: Decimal) -> int:
    """The exponent of a finite Decimal; NaN and infinity (whose exponent is a letter) are a
    TypeError, as comparing that letter with a number was."""
    exponent = number.as_tuple().exponent
    if isinstance(exponent, str):
        raise TypeError(f"ROUND needs a finite number, got {_describe(number)}")
    return exponent
