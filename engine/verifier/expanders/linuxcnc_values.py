"""LinuxCNC values (docs/reference/linuxcnc-lathe.md §2): numbers, parameters `#1`, `#<name>`,
`#<_global>`, `##1`, and expressions `[ … ]` with the operators and functions of the RS274/NGC
interpreter, read from a line whose comments and spaces are gone (engine.verifier.expanders.
linuxcnc_lines). Operators and functions are tables; nothing is handed to Python's eval.

Precedence (LinuxCNC gcode/overview "Binary Operators"): ** first, then * / MOD, then + -, then
EQ NE GT GE LT LE, then AND OR XOR; equal precedence left to right. Angles are in degrees.
Division by zero, a root of a negative number and a value that is not finite are refused: the
control stops the program with an error there."""
from __future__ import annotations

import math
import re
from collections.abc import Callable

from ..refusals import Refused

NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")
MAX_DIGITS = 15       # more digits than any length or speed of a lathe program needs


def _divide(a: float, b: float) -> float:
    if b == 0:
        raise Refused("a division by zero")
    return a / b


def _mod(a: float, b: float) -> float:
    """LinuxCNC: fmod, made positive by adding |b| (execute_binary1 "always a positive answer")."""
    if b == 0:
        raise Refused("MOD by zero")
    rest = math.fmod(a, b)
    return rest + abs(b) if rest < 0 else rest


def _power(a: float, b: float) -> float:
    if a < 0 and math.floor(b) != b:
        raise Refused("a negative number raised to a power that is not whole")
    return float(a ** b)


def _truth(value: bool) -> float:
    return 1.0 if value else 0.0


def _equal(a: float, b: float) -> bool:
    """EQ, NE, LE, GE compare within TOLERANCE_EQUAL = 1e-6 (rs274ngc interp_internal.hh)."""
    return abs(a - b) < TOLERANCE_EQUAL


TOLERANCE_EQUAL = 1e-6


# name -> (precedence, function); higher binds first
BINARY: dict[str, tuple[int, Callable[[float, float], float]]] = {
    "**": (5, _power), "*": (4, lambda a, b: a * b), "/": (4, _divide), "mod": (4, _mod),
    "+": (3, lambda a, b: a + b), "-": (3, lambda a, b: a - b),
    "eq": (2, lambda a, b: _truth(_equal(a, b))), "ne": (2, lambda a, b: _truth(not _equal(a, b))),
    "gt": (2, lambda a, b: _truth(a > b)), "ge": (2, lambda a, b: _truth(_equal(a, b) or a >= b)),
    "lt": (2, lambda a, b: _truth(a < b)), "le": (2, lambda a, b: _truth(_equal(a, b) or a <= b)),
    "and": (1, lambda a, b: _truth(bool(a) and bool(b))), "or": (1, lambda a, b: _truth(bool(a) or bool(b))),
    "xor": (1, lambda a, b: _truth(bool(a) != bool(b)))}
OPERATORS = sorted(BINARY, key=len, reverse=True)     # "**" before "*"


def _root(value: float) -> float:
    if value < 0:
        raise Refused(f"SQRT of a negative number ({value:g})")
    return math.sqrt(value)


def _log(value: float) -> float:
    if value <= 0:
        raise Refused(f"LN of {value:g}, not above 0")
    return math.log(value)


def _arc(function: Callable[[float], float]) -> Callable[[float], float]:
    def inverse(value: float) -> float:
        if not -1 <= value <= 1:
            raise Refused(f"ACOS/ASIN of {value:g}, outside -1 … 1")
        return math.degrees(function(value))
    return inverse


UNARY: dict[str, Callable[[float], float]] = {
    "abs": abs, "acos": _arc(math.acos), "asin": _arc(math.asin),
    "cos": lambda v: math.cos(math.radians(v)), "sin": lambda v: math.sin(math.radians(v)),
    "tan": lambda v: math.tan(math.radians(v)), "exp": math.exp, "fix": lambda v: float(math.floor(v)),
    "fup": lambda v: float(math.ceil(v)), "round": lambda v: float(math.floor(v + 0.5)), "ln": _log, "sqrt": _root}
FUNCTIONS = sorted([*UNARY, "atan", "exists"], key=len, reverse=True)


class Values:
    """Reads values from one line (lower case, no spaces) at `at`; `lookup` gives a parameter's value."""

    def __init__(self, text: str, lookup: Callable[[str], float], defined: Callable[[str], bool]) -> None:
        self.text, self.at, self.lookup, self.defined = text, 0, lookup, defined

    def peek(self, count: int = 1) -> str:
        return self.text[self.at:self.at + count]

    def expect(self, what: str) -> None:
        if not self.text.startswith(what, self.at):
            raise Refused(f"{what!r} expected at {self.text[self.at:self.at + 12] or 'the end'!r}")
        self.at += len(what)

    def value(self) -> float:
        """A real value: a number, a parameter, an expression, a function, with a sign."""
        char = self.peek()
        if char in "+-" and self.peek(2)[1:] in ("#", "[", *(f[0] for f in FUNCTIONS)):
            self.at += 1
            return -self.value() if char == "-" else self.value()
        if char == "[":
            return self.expression()
        if char == "#":
            return self.lookup(self.parameter())
        if char.isalpha():
            return self._function()
        return self._number()

    def _number(self) -> float:
        match = NUMBER.match(self.text, self.at)
        if match is None:
            raise Refused(f"a number expected at {self.text[self.at:self.at + 12] or 'the end'!r}")
        if sum(c.isdigit() for c in match.group()) > MAX_DIGITS:
            raise Refused(f"{match.group()[:20]}: more digits than any value of a lathe program")
        self.at = match.end()
        return float(match.group())

    def parameter(self) -> str:
        """The key of a parameter reference at `#`: "5", "<name>" (lower case), or an indirect ##…"""
        self.expect("#")
        if self.peek() == "<":
            end = self.text.find(">", self.at)
            if end < 0:
                raise Refused("a named parameter #<… without its closing >")
            name, self.at = self.text[self.at:end + 1], end + 1
            return name
        number = self.value() if self.peek() in "#[" else self._number()
        if number != int(number) or not 0 < number < 100_000:
            raise Refused(f"#{number:g} is not a parameter number")
        return str(int(number))

    def expression(self) -> float:
        """`[ … ]`: values joined by binary operators, precedence climbing."""
        self.expect("[")
        result = self._climb(self.value(), 1)
        self.expect("]")
        return _finite(result)

    def _climb(self, left: float, least: int) -> float:
        while (operator := self._operator()) and BINARY[operator][0] >= least:
            precedence, function = BINARY[operator]
            self.at += len(operator)
            right = self.value()
            while (following := self._operator()) and BINARY[following][0] > precedence:
                right = self._climb(right, BINARY[following][0])
            left = _apply(function, left, right)
        return left

    def _operator(self) -> str | None:
        return next((name for name in OPERATORS if self.text.startswith(name, self.at)), None)

    def _function(self) -> float:
        name = next((f for f in FUNCTIONS if self.text.startswith(f + "[", self.at)), None)
        if name is None:
            raise Refused(f"{self.text[self.at:self.at + 12]!r} is not a value, function or word of LinuxCNC")
        self.at += len(name)
        if name == "exists":
            return self._exists()
        argument = self.expression()
        if name != "atan":
            return _apply(UNARY[name], argument)
        self.expect("/")
        return math.degrees(math.atan2(argument, self.expression()))

    def _exists(self) -> float:
        self.expect("[")
        key = self.parameter()
        self.expect("]")
        return _truth(self.defined(key))


def _apply(function: Callable[..., float], *arguments: float) -> float:
    try:
        return _finite(function(*arguments))
    except (OverflowError, ZeroDivisionError):
        raise Refused("an expression whose value is not a finite number") from None


def _finite(value: float) -> float:
    if isinstance(value, complex) or not math.isfinite(value):
        raise Refused("an expression whose value is not a finite number")
    return float(value)
