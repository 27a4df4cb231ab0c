"""The arithmetic of Fanuc custom macro B in an ISO lathe program (issue 27): #variables and
bracketed expressions, read by a bounded parser and evaluated over the values this program has
set, never by Python's eval.

Order of operations (Fanuc operator's manual, "Custom macro", "Arithmetic and logic operation"):
functions and brackets first; then * / AND MOD; then + - OR XOR; then the comparisons EQ NE GT GE
LT LE, weakest; a comparison's TRUE/FALSE is not a number (stored, or used in arithmetic or as a
condition alone, it is an alarm), brackets nest five deep (alarm 118). FIX goes towards zero, FUP
away from zero. Angles are in degrees (SIN[30] is 0.5). Variables: #1–#33 local, #100–#199 and
#500–#999 common. A variable the program reads before setting it is vacant (or, #500–#999, holds
what an earlier program left on the control): refused naming it, never taken as 0. The system
variables #1000 and above (interface signals, clocks, tool offsets, positions, modal states) hold
values only the control has: refused naming the variable. Facts: docs/reference/iso-lathe.md."""
from __future__ import annotations

import math
import re
from collections.abc import Callable

from ..refusals import Refused

MAX_LENGTH = 400        # characters of one expression: no real program's arithmetic is longer
MAX_DEPTH = 32          # nested brackets and operators
TOKEN = re.compile(r"\s*(?:(?P<number>\d+\.?\d*|\.\d+)|(?P<name>[A-Z]+)|(?P<op>[-+*/#\[\]]))")
# variable number ranges a program may set and read (custom macro B)
WRITABLE = (range(1, 34), range(100, 200), range(500, 1000))
# what the system variables hold (Fanuc 0i-TD/TF "System variables"): why the verifier cannot know them
SYSTEM = ((1000, 1200, "interface signals of the machine's PLC"), (2000, 3000, "tool compensation values"),
          (3000, 3001, "the alarm it raises"), (3001, 3003, "clocks"), (3003, 3100, "control settings"),
          (3100, 4000, "control states and counters"), (4000, 5000, "modal information of the block before"),
          (5000, 6000, "positions and work offsets"))


class MacroError(Refused):
    """A macro construct that cannot be followed; the reason names it."""


def _degrees(function: Callable[[float], float]) -> Callable[[float], float]:
    return lambda value: function(math.radians(value))


def _sqrt(value: float) -> float:
    if value < 0:
        raise MacroError(f"SQRT[{value:g}]: the square root of a negative number (alarm on the control)")
    return math.sqrt(value)


def _ln(value: float) -> float:
    if value <= 0:
        raise MacroError(f"LN[{value:g}]: the logarithm of a number not above 0 (alarm on the control)")
    return math.log(value)


def round_half_away(value: float) -> float:
    """Fanuc ROUND: to the nearest whole number, a half away from zero (ROUND[-1.5] is -2)."""
    return math.copysign(math.floor(abs(value) + 0.5), value)


# name -> function of one bracketed argument (Fanuc "Arithmetic and logic operation")
FUNCTIONS: dict[str, Callable[[float], float]] = {
    "SIN": _degrees(math.sin), "COS": _degrees(math.cos), "TAN": _degrees(math.tan), "SQRT": _sqrt,
    "ABS": abs, "ROUND": round_half_away, "FIX": lambda v: float(math.trunc(v)),
    "FUP": lambda v: math.copysign(math.ceil(abs(v)), v), "LN": _ln, "EXP": math.exp,
}
# FIX drops the fraction (towards zero: FIX[-1.2] is -1), FUP rounds away from zero (FUP[-1.2] is -2):
# Fanuc operator's manual, custom macro, "Rounding up and down to an integer"; docs/reference/iso-lathe.md.
# functions whose result a parameter of the control chooses (ATAN/ASIN/ACOS ranges: parameter 6004#0 NAT)
UNKNOWN_FUNCTIONS = {"ATAN": "parameter 6004#0", "ASIN": "parameter 6004#0", "ACOS": "parameter 6004#0",
                     "BIN": "BCD conversion", "BCD": "BCD conversion", "POPEN": "the reader", "BPRNT": "the printer",
                     "DPRNT": "the printer"}


def _logical(name: str, test: Callable[[bool, bool], bool]) -> Callable[[float, float], float]:
    def combine(a: float, b: float) -> float:
        if a not in (0.0, 1.0) or b not in (0.0, 1.0):
            raise MacroError(f"{name} of {a:g} and {b:g}: bitwise logic on values other than 0 and 1 is not followed")
        return float(test(bool(a), bool(b)))
    return combine


def _divide(a: float, b: float) -> float:
    if b == 0:
        raise MacroError(f"{a:g}/0: a division by zero (alarm on the control)")
    return a / b


def _mod(a: float, b: float) -> float:
    if round_half_away(b) == 0:
        raise MacroError(f"{a:g} MOD 0: a division by zero (alarm on the control)")
    return float(math.fmod(round_half_away(a), round_half_away(b)))


class Truth(float):
    """The TRUE (1) or FALSE (0) of a comparison: Fanuc keeps it apart from numbers (it cannot be
    stored in a variable, used in arithmetic, or stand for a number in a word)."""


COMPARISONS = frozenset({"EQ", "NE", "GT", "GE", "LT", "LE"})
LOGIC = frozenset({"AND", "OR", "XOR"})
MAX_BRACKETS = 5        # Fanuc: brackets nest five deep, function brackets included (alarm 118)


def apply(name: str, operator: Callable[[float, float], float], a: float, b: float) -> float:
    """One binary operation with Fanuc's types: a comparison of two numbers gives TRUE/FALSE;
    AND/OR/XOR join two comparisons or two numbers; arithmetic takes numbers only."""
    truths = isinstance(a, Truth), isinstance(b, Truth)
    if name in LOGIC and truths[0] == truths[1]:
        return Truth(operator(a, b)) if truths[0] else operator(a, b)
    if any(truths):
        raise MacroError(f"{name} with the TRUE/FALSE of a comparison as a number (an alarm on the control)")
    return Truth(operator(a, b)) if name in COMPARISONS else operator(a, b)


def number(value: float, where: str) -> float:
    if isinstance(value, Truth):
        raise MacroError(f"{where}: the TRUE/FALSE of a comparison is not a number (an alarm on the control)")
    return value


def check_brackets(code: str) -> None:
    """Fanuc alarm 118: brackets nested more than five deep in one statement or block."""
    depth = deepest = 0
    for char in code:
        depth += {"[": 1, "]": -1}.get(char, 0)
        deepest = max(deepest, depth)
    if deepest > MAX_BRACKETS:
        raise MacroError(f"brackets nested {deepest} deep: Fanuc allows {MAX_BRACKETS} (alarm 118)")


# binary operators from the weakest to the strongest
LEVELS: tuple[dict[str, Callable[[float, float], float]], ...] = (
    {"EQ": lambda a, b: float(a == b), "NE": lambda a, b: float(a != b), "GT": lambda a, b: float(a > b),
     "GE": lambda a, b: float(a >= b), "LT": lambda a, b: float(a < b), "LE": lambda a, b: float(a <= b)},
    {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "OR": _logical("OR", lambda a, b: a or b),
     "XOR": _logical("XOR", lambda a, b: a != b)},
    {"*": lambda a, b: a * b, "/": _divide, "AND": _logical("AND", lambda a, b: a and b), "MOD": _mod},
)


def variable_number(value: float) -> int:
    """#[expression]: the variable whose number is the value rounded (Fanuc rounds it)."""
    return int(round_half_away(value))


def read_variable(variables: dict[int, float], number: int) -> float:
    if number == 0:
        raise MacroError("#0 is always vacant (the null variable): a value the verifier cannot follow")
    if number >= 1000:
        raise MacroError(f"#{number} is a system variable: it holds {_system(number)}, a value only the control has")
    if not any(number in span for span in WRITABLE):
        raise MacroError(f"#{number} is not a variable of custom macro B (#1–#33, #100–#199, #500–#999)")
    if number not in variables:
        where = "a value an earlier program left on the control" if number >= 500 else "vacant"
        raise MacroError(f"#{number} is read before this program sets it: it is {where}, which the verifier "
                         "cannot know")
    return variables[number]


def write_variable(variables: dict[int, float], number: int, value: float) -> None:
    if number >= 1000:
        raise MacroError(f"#{number} is a system variable: setting it changes {_system(number)}, which the "
                         "verifier does not follow")
    if not any(number in span for span in WRITABLE):
        raise MacroError(f"#{number} is not a variable of custom macro B (#1–#33, #100–#199, #500–#999)")
    variables[number] = value


def _system(number: int) -> str:
    return next((what for low, high, what in SYSTEM if low <= number < high), "a setting of the control")


def tokens(text: str) -> list[str]:
    if len(text) > MAX_LENGTH:
        raise MacroError(f"an expression of more than {MAX_LENGTH} characters")
    found, at = [], 0
    while at < len(text):
        if not text[at:].strip():
            break
        match = TOKEN.match(text, at)
        if match is None:
            raise MacroError(f"{text[at:].strip()!r} is not part of a macro expression")
        found.append(match.group(match.lastgroup or "op"))
        at = match.end()
    return found


class Expression:
    """One expression's tokens, evaluated by recursive descent over the program's variables."""

    def __init__(self, text: str, variables: dict[int, float]) -> None:
        self.tokens, self.at, self.variables, self.depth = tokens(text), 0, variables, 0

    def value(self) -> float:
        result = self._level(0)
        if self.at != len(self.tokens):
            raise MacroError(f"{' '.join(self.tokens[self.at:])!r} after a whole expression")
        return result

    def _peek(self) -> str | None:
        return self.tokens[self.at] if self.at < len(self.tokens) else None

    def _next(self, what: str) -> str:
        token = self._peek()
        if token is None:
            raise MacroError(f"an expression ends where {what} should follow")
        self.at += 1
        return token

    def _level(self, level: int) -> float:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise MacroError(f"an expression nested more than {MAX_DEPTH} deep")
        if level == len(LEVELS):
            left = self._unary()
        else:
            left = self._level(level + 1)
            while self._peek() in LEVELS[level]:
                name = self._next("an operator")
                left = apply(name, LEVELS[level][name], left, self._level(level + 1))
        self.depth -= 1
        return left

    def _unary(self) -> float:
        if self._peek() in ("-", "+"):
            sign = -1.0 if self._next("a sign") == "-" else 1.0
            return sign * number(self._unary(), "a sign")
        return self._primary()

    def _primary(self) -> float:
        token = self._next("a value")
        if token == "[":
            return self._bracket()
        if token == "#":
            return read_variable(self.variables, self.reference())
        if token in FUNCTIONS:
            if self._next("its [") != "[":
                raise MacroError(f"{token} without its bracketed argument")
            return FUNCTIONS[token](number(self._bracket(), token))
        if token in UNKNOWN_FUNCTIONS:
            raise MacroError(f"{token}: its result depends on {UNKNOWN_FUNCTIONS[token]} of the control")
        if token[0].isdigit() or token[0] == ".":
            return float(token)
        raise MacroError(f"{token!r} is not a value, a variable or a function of custom macro B")

    def _bracket(self) -> float:
        inner = self._level(0)
        if self._next("]") != "]":
            raise MacroError("a [ without its ]")
        return inner

    def reference(self) -> int:
        """The number after #: written (#501) or computed (#[#1+500])."""
        token = self._next("a variable number")
        if token == "[":
            return variable_number(number(self._bracket(), "#[...]"))
        if not token.isdigit():
            raise MacroError(f"#{token} is not a variable (# and its number)")
        return int(token)


def evaluate(text: str, variables: dict[int, float]) -> float:
    """An arithmetic expression's value (a number: `#1=[1 LT 2]` is refused)."""
    return number(Expression(text, variables).value(), repr(text.strip()))


def condition(text: str, variables: dict[int, float]) -> bool:
    """The condition of IF/WHILE: a comparison (EQ NE GT GE LT LE, or comparisons joined by AND OR
    XOR); a bare number (`IF [#1] GOTO 10`) is refused, as Fanuc alarms on it."""
    value = Expression(text, variables).value()
    if not isinstance(value, Truth):
        raise MacroError(f"[{text.strip()}] is not a comparison: IF and WHILE need EQ NE GT GE LT or LE "
                         "(an alarm on the control)")
    return float(value) != 0.0
