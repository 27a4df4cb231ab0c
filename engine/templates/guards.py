"""Bounds on what a template expression may build, as functions the evaluator (asteval) calls
in place of the operators that can allocate without bound, and of str() and round(); asteval's
own guards run behind ours. Every value an expression builds has a size of at most MAX_SIZE
(characters of a string; elements of a list or tuple, nested ones counted, so a list of
65,536 references to a list of 65,536 is 2^32, not 65,536): comparing, printing or formatting
a value is then bounded too. Every value a guard builds is paid for from the instantiation's budget
(engine.templates.budget), which bounds what a whole run builds and its time. An f-string field or
str() prints a number or a text, never a list or tuple: an NC word is one value, and a printed
container would cost far more than its size. nc_path checks its formats with the same
check_format_spec."""
from __future__ import annotations

import ast
import re
import reprlib
import threading
from decimal import Decimal
from typing import Literal, overload

from .asteval_import import asteval_safe_pow
from .budget import paid

MAX_SIZE = 1 << 16                 # characters or (nested) elements of any value an expression builds
MAX_STRING_LENGTH = MAX_SIZE
MAX_INT_BITS = 4_096               # bits of any integer an expression builds
MAX_FORMAT_WIDTH = 200             # width/precision in a format spec
SEQUENCES = (str, tuple, list)
PRINTABLE = (str, int, float, Decimal, type(None))   # bool is an int
INT_DIGITS_PER_UNIT = 64           # an integer counts one unit of size per 64 bits (printing it costs that)
_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = _SHORT.maxlong = 60
_SHORT.maxlist = _SHORT.maxtuple = 6
_SHORT.maxlevel = 2


# CPython 3.11 counts the AST converter's recursion depth in state that threads share: two
# threads parsing at once may fail with "SystemError: AST constructor recursion depth mismatch"
# (seen with editors, the refactor and runners in one process). Parsing is quick; one at a time.
_PARSING = threading.Lock()


@overload
def parse_python(text: str, mode: Literal["eval"] = "eval") -> ast.Expression: ...
@overload
def parse_python(text: str, mode: Literal["exec"]) -> ast.Module: ...
@overload
def parse_python(text: str, mode: str) -> ast.AST: ...
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
            extra, inner = _nested(item)
            total += extra
            pending.extend(inner)
        elif _big_int(item):
            total += item.bit_length() // INT_DIGITS_PER_UNIT
        else:
            total += 1
    return total


_SCALARS = frozenset({float, bool, type(None)})
_NUMBERS = frozenset({int, float, bool})
_TEXTS = frozenset({str})
_BIG = 1 << INT_DIGITS_PER_UNIT


def _nested(sequence) -> tuple[int, list]:
    """What the elements of a list or tuple add beyond their slots: the characters of its texts
    (counted), and its sequences and big integers (to count). The flat cases are found at C speed:
    a guard's count must cost little next to the value it guards."""
    kinds = set(map(type, sequence))
    if kinds <= _SCALARS or kinds <= _NUMBERS and max(map(abs, sequence), default=0) < _BIG:
        return 0, []   # a NaN as the maximum takes the general way below
    if kinds == _TEXTS:
        return sum(map(len, sequence)), []
    return 0, [element for element in sequence if isinstance(element, SEQUENCES) or _big_int(element)]


def _big_int(value) -> bool:
    return type(value) is int and value.bit_length() > INT_DIGITS_PER_UNIT


def guard_size(result):
    """A built value (f-string, list or tuple display) of at most MAX_SIZE, paid for."""
    if isinstance(result, SEQUENCES) and size(result) > MAX_SIZE:
        raise ValueError(f"result larger than {MAX_SIZE} characters or elements")
    return paid(result)


def built(result):
    """A value a slice copied: never larger than what it was cut from, but paid for."""
    return paid(result)


def safe_pow(base, exponent):
    """Integer powers bounded in bits; then asteval's own safe_pow (exponent at most 10,000)."""
    if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1:
        if exponent * abs(base).bit_length() > MAX_INT_BITS:
            raise ValueError(f"power too large (more than {MAX_INT_BITS} bits)")
    return paid(asteval_safe_pow(base, exponent))


def safe_mult(left, right):
    if isinstance(left, int) and isinstance(right, int):
        if _bits(left) + _bits(right) > MAX_INT_BITS:
            raise ValueError(f"product too large (more than {MAX_INT_BITS} bits)")
    for sequence, count in ((left, right), (right, left)):
        if isinstance(sequence, SEQUENCES) and isinstance(count, int) and count > 0:
            if size(sequence, MAX_SIZE // count + 1) * count > MAX_SIZE:
                raise ValueError(f"repetition larger than {MAX_SIZE} characters or elements")
    return paid(left * right)


def safe_add(left, right):
    if isinstance(left, SEQUENCES) and isinstance(right, type(left)):
        if size(left) + size(right) > MAX_SIZE:
            raise ValueError(f"result larger than {MAX_SIZE} characters or elements")
    return paid(left + right)


def safe_lshift(left, right):
    if isinstance(right, int) and right + _bits(left) > MAX_INT_BITS:
        raise ValueError(f"shift too large (more than {MAX_INT_BITS} bits)")
    return paid(left << right)


def safe_mod(left, right):
    if isinstance(left, str):
        raise ValueError("'%' string formatting is not allowed; use an f-string")
    return paid(left % right)


_FORMAT_NUMBERS = re.compile(r"\d+")


def check_format_spec(spec: str) -> None:
    if any(int(number) > MAX_FORMAT_WIDTH for number in _FORMAT_NUMBERS.findall(spec)):
        raise ValueError(f"format width or precision above {MAX_FORMAT_WIDTH} in {spec!r}")


def safe_format(value, spec: str) -> str:
    """format() with the width and precision of the spec bounded."""
    check_format_spec(spec)
    check_printable(value)
    return paid(format(value, spec))


def safe_str(value=""):
    if isinstance(value, int) and _bits(value) > MAX_INT_BITS:
        raise ValueError("integer too large to print")
    check_printable(value)
    return paid(str(value))


def safe_int(value=0, *base):
    """int(), its result bounded like any integer an expression builds."""
    if isinstance(value, str) and len(value) > MAX_INT_BITS:
        raise ValueError(f"int() of a text longer than {MAX_INT_BITS} characters")
    result = int(value, *base)
    if _bits(result) > MAX_INT_BITS:
        raise ValueError(f"integer too large (more than {MAX_INT_BITS} bits)")
    return paid(result)


def check_printable(value) -> None:
    """A value an f-string field or str() may print: a number or a text of at most a quarter of
    MAX_SIZE; never a list, tuple or other object (an NC word is one value; print its elements)."""
    if not isinstance(value, PRINTABLE):
        raise ValueError(f"a {type(value).__name__} cannot be printed into an NC line; print its elements")
    if (isinstance(value, str) or _big_int(value)) and size(value, MAX_SIZE // 4) > MAX_SIZE // 4:
        raise ValueError(f"value too large to print (more than {MAX_SIZE // 4} characters or digits)")


def safe_round(value, digits=None):
    if digits is not None and abs(digits) > MAX_FORMAT_WIDTH:
        raise ValueError(f"round() to more than {MAX_FORMAT_WIDTH} digits")
    return paid(round(value) if digits is None else round(value, digits))
