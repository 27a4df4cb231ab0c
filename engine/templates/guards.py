"""Bounds on what a template expression may build, as functions the evaluator (asteval) calls
in place of the operators that can allocate without bound, and of str() and round(); asteval's
own guards run behind ours. Every value an expression builds has a size of at most MAX_SIZE
(characters of a string; elements of a list or tuple, nested ones counted, so a list of
65,536 references to a list of 65,536 is 2^32, not 65,536): comparing, printing or formatting
a value is then bounded too. nc_path checks its formats with the same check_format_spec."""
from __future__ import annotations

import ast
import re
import reprlib
import threading

from .asteval_import import asteval_safe_pow

MAX_SIZE = 1 << 16                 # characters or (nested) elements of any value an expression builds
MAX_STRING_LENGTH = MAX_SIZE
MAX_INT_BITS = 4_096               # bits of any integer an expression builds
MAX_FORMAT_WIDTH = 200             # width/precision in a format spec
SEQUENCES = (str, tuple, list)
INT_DIGITS_PER_UNIT = 64           # an integer counts one unit of size per 64 bits (printing it costs that)
_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = _SHORT.maxlong = 60
_SHORT.maxlist = _SHORT.maxtuple = 6
_SHORT.maxlevel = 2


# CPython 3.11 counts the AST converter's recursion depth in state that threads share: two
# threads parsing at once may fail with "SystemError: AST constructor recursion depth mismatch"
# (seen with editors, the refactor and runners in one process). Parsing is quick; one at a time.
_PARSING = threading.Lock()


def parse_python(text: str, mode: str = "eval") -> ast.AST:
    """ast.parse, one thread at a time."""
    with _PARSING:
        return ast.parse(text, mode=mode)


def short_repr(value) -> str:
    """A value as a message shows it: a few elements, a few dozen characters, never the whole."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 256:
        return f"<integer of {value.bit_length()} bits>"
    return _SHORT.repr(value)


def _bits(value) -> int:
    return value.bit_length() if isinstance(value, int) else 0


def size(value, limit: int = MAX_SIZE) -> int:
    """Characters of a string, elements of a list or tuple with nested ones counted (each time
    they occur); 1 for anything else. Stops counting once past `limit`."""
    total, pending = 0, [value]
    while pending and total <= limit:
        item = pending.pop()
        if isinstance(item, str):
            total += len(item)
        elif isinstance(item, (tuple, list)):
            total += len(item)
            if total > limit:
                break
            pending.extend(element for element in item if isinstance(element, SEQUENCES) or _big_int(element))
        elif _big_int(item):
            total += item.bit_length() // INT_DIGITS_PER_UNIT
        else:
            total += 1
    return total


def _big_int(value) -> bool:
    return type(value) is int and value.bit_length() > INT_DIGITS_PER_UNIT


def guard_size(result):
    """A built value (f-string, list or tuple display) of at most MAX_SIZE."""
    if isinstance(result, SEQUENCES) and size(result) > MAX_SIZE:
        raise ValueError(f"result larger than {MAX_SIZE} characters or elements")
    return result


def safe_pow(base, exponent):
    """Integer powers bounded in bits; then asteval's own safe_pow (exponent at most 10,000)."""
    if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1:
        if exponent * abs(base).bit_length() > MAX_INT_BITS:
            raise ValueError(f"power too large (more than {MAX_INT_BITS} bits)")
    return asteval_safe_pow(base, exponent)


def safe_mult(left, right):
    if isinstance(left, int) and isinstance(right, int):
        if _bits(left) + _bits(right) > MAX_INT_BITS:
            raise ValueError(f"product too large (more than {MAX_INT_BITS} bits)")
    for sequence, count in ((left, right), (right, left)):
        if isinstance(sequence, SEQUENCES) and isinstance(count, int) and count > 0:
            if size(sequence, MAX_SIZE // count + 1) * count > MAX_SIZE:
                raise ValueError(f"repetition larger than {MAX_SIZE} characters or elements")
    return left * right


def safe_add(left, right):
    if isinstance(left, SEQUENCES) and isinstance(right, type(left)):
        if size(left) + size(right) > MAX_SIZE:
            raise ValueError(f"result larger than {MAX_SIZE} characters or elements")
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
    check_printable(value)
    return format(value, spec)


def safe_str(value=""):
    if isinstance(value, int) and _bits(value) > MAX_INT_BITS:
        raise ValueError("integer too large to print")
    check_printable(value)
    return guard_size(str(value))


def safe_int(value=0, *base):
    """int(), its result bounded like any integer an expression builds."""
    if isinstance(value, str) and len(value) > MAX_INT_BITS:
        raise ValueError(f"int() of a text longer than {MAX_INT_BITS} characters")
    result = int(value, *base)
    if _bits(result) > MAX_INT_BITS:
        raise ValueError(f"integer too large (more than {MAX_INT_BITS} bits)")
    return result


def check_printable(value) -> None:
    """A value an f-string field or str() may print: at most a quarter of MAX_SIZE."""
    if (isinstance(value, SEQUENCES) or _big_int(value)) and size(value, MAX_SIZE // 4) > MAX_SIZE // 4:
        raise ValueError(f"value too large to print (more than {MAX_SIZE // 4} characters or elements)")


def safe_round(value, digits=None):
    if digits is not None and abs(digits) > MAX_FORMAT_WIDTH:
        raise ValueError(f"round() to more than {MAX_FORMAT_WIDTH} digits")
    return round(value) if digits is None else round(value, digits)
