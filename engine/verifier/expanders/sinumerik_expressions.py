"""The arithmetic of 840D programs (R-parameters, DEF variables, conditions), read by a bounded
parser and evaluated over the values this program has set, never by Python's eval.

Operators and their order are the control's (reference sinumerik-lathe §S3: NOT; * / DIV MOD; + -; AND; XOR; OR;
then the comparisons == <> > < >= <=, weakest), angles in degrees (SIN(30) is 0.5). A value the
program has not set (an R-parameter it reads before assigning it, a system variable $…) is the
control's and unknown here: it is refused, not taken as 0. Expressions are bounded in length and
nesting so that no program text can make the reader work without end."""
from __future__ import annotations

import math
import re
from collections.abc import Callable
from functools import lru_cache
from typing import Any

from ..numbers import plain_decimal
from ..refusals import Refused

MAX_LENGTH = 400        # characters of one expression: no real program's arithmetic is longer
MAX_DEPTH = 32          # nested parentheses and operators
TOKEN = re.compile(r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+))|(?P<name>\$?[A-Z_][A-Z0-9_]*)"
                   r"|(?P<op>==|<>|<=|>=|[-+*/()<>,\[\]]))")


def _degrees(function: Callable[[float], float]) -> Callable[[float], float]:
    return lambda value: function(math.radians(value))


def _inverse(function: Callable[[float], float]) -> Callable[[float], float]:
    return lambda value: math.degrees(function(value))


def _sqrt(value: float) -> float:
    if value < 0:
        raise Refused(f"SQRT({value:g}): the square root of a negative number")
    return math.sqrt(value)


def round_half_up(value: float) -> float:
    """ROUND, and a REAL assigned to an INT: "a fraction >= 0.5 is rounded up, otherwise rounded down"
    ([PGA-2000] §1.9, reference sinumerik-lathe §S2), so 2.5 is 3, not Python's half-to-even 2. For a
    negative value with a fraction of exactly 0.5 "up" may mean -2 or -3: the manual does not say, refused."""
    if value < 0 and value - math.floor(value) == 0.5:
        raise Refused(f"rounding {value:g} to a whole number: the manual rounds a fraction of 0.5 up, and does "
                      "not say whether a negative half goes to the larger or the smaller whole number")
    return float(math.floor(abs(value) + 0.5)) * (1 if value >= 0 else -1)


# name -> (number of arguments, function): the control's arithmetic functions (reference sinumerik-lathe §S3)
FUNCTIONS: dict[str, tuple[int, Callable[..., float]]] = {
    "SIN": (1, _degrees(math.sin)), "COS": (1, _degrees(math.cos)), "TAN": (1, _degrees(math.tan)),
    "ASIN": (1, _inverse(math.asin)), "ACOS": (1, _inverse(math.acos)),
    "ATAN2": (2, lambda y, x: math.degrees(math.atan2(y, x))), "SQRT": (1, _sqrt), "ABS": (1, abs),
    "POT": (1, lambda value: value * value), "TRUNC": (1, lambda value: float(math.trunc(value))),
    "ROUND": (1, round_half_up), "MINVAL": (2, min), "MAXVAL": (2, max),
    "EXP": (1, math.exp), "LN": (1, math.log),
}
CONSTANTS = {"TRUE": 1.0, "FALSE": 0.0}
# binary operators from the weakest to the strongest (reference sinumerik-lathe §S3)
LEVELS: tuple[dict[str, Callable[[float, float], float]], ...] = (
    {"==": lambda a, b: float(a == b), "<>": lambda a, b: float(a != b), ">": lambda a, b: float(a > b),
     "<": lambda a, b: float(a < b), ">=": lambda a, b: float(a >= b), "<=": lambda a, b: float(a <= b)},
    {"OR": lambda a, b: float(bool(a) or bool(b))},
    {"XOR": lambda a, b: float(bool(a) != bool(b))},
    {"AND": lambda a, b: float(bool(a) and bool(b))},
    {"+": lambda a, b: a + b, "-": lambda a, b: a - b},
    {"*": lambda a, b: a * b, "/": lambda a, b: _divide(a, b),
     "DIV": lambda a, b: float(_whole_quotient("DIV", a, b)[0]),
     "MOD": lambda a, b: float(_whole_quotient("MOD", a, b)[1])},
)
Tree = tuple[Any, ...]   # ("number", v) | ("name", n) | ("call", n, args) | ("not", t) | ("neg", t) | (op, left, right)


def _whole_quotient(operator: str, a: float, b: float) -> tuple[int, int]:
    """DIV and MOD: the whole quotient and the remainder of a division of whole numbers [PGA-JP].
    For whole numbers of which none is negative every reading agrees (7 DIV 2 = 3, 7 MOD 3 = 1);
    the manuals read here give no rule for a negative or fractional operand (truncated or floored,
    the remainder's sign), so such an operand is refused (reference sinumerik-lathe §S3)."""
    if a < 0 or b <= 0 or a != math.floor(a) or b != math.floor(b):
        raise Refused(f"{a:g} {operator} {b:g}: {operator} is evaluated for whole numbers, none negative, "
                      "and a divisor above 0; the rule for other operands is not confirmed")
    return divmod(int(a), int(b))


def _divide(a: float, b: float) -> float:
    if b == 0:
        raise Refused("a division by 0")
    return a / b


def evaluate(text: str, values: dict[str, float]) -> float:
    """The value of `text` with the names of `values`; Refused names what cannot be evaluated."""
    value = _value(parse(text), values)
    if not math.isfinite(value):
        raise Refused(f"{text} is not a finite number")
    return value


@lru_cache(maxsize=4096)
def parse(text: str) -> Tree:
    """The tree of `text` (kept per text: a loop evaluates the same expressions again)."""
    if len(text) > MAX_LENGTH:
        raise Refused(f"an expression of {len(text)} characters, more than {MAX_LENGTH}")
    reader = _Reader(_tokens(text), text)
    tree = reader.level(0, 0)
    if reader.position != len(reader.tokens):
        raise Refused(f"{text}: not an expression the control reads ({reader.rest()} left over)")
    return tree


def names_read(text: str) -> frozenset[str]:
    """The names an expression reads (R1, a DEF variable); none for text that is no expression
    (a string, a call's arguments), which is refused where it is evaluated."""
    try:
        tree = parse(text)
    except Refused:
        return frozenset()
    return frozenset(_names_in(tree))


def _names_in(tree: Tree) -> list[str]:
    if tree[0] == "name":
        return [tree[1]]
    if tree[0] == "number":
        return []
    branches = tree[2] if tree[0] == "call" else tree[1:]
    return [name for branch in branches for name in _names_in(branch)]


def _tokens(text: str) -> list[tuple[str, str]]:
    tokens, position = [], 0
    while position < len(text):
        match = TOKEN.match(text, position)
        if match is None or match.end() == position:
            if not text[position:].strip():
                break
            raise Refused(f"{text}: {text[position:position + 12]!r} is not arithmetic the verifier reads")
        kind = match.lastgroup or "op"
        tokens.append((kind, match.group(kind)))
        position = match.end()
    return tokens


class _Reader:
    def __init__(self, tokens: list[tuple[str, str]], text: str) -> None:
        self.tokens, self.text, self.position = tokens, text, 0

    def rest(self) -> str:
        return " ".join(value for _, value in self.tokens[self.position:])

    def peek(self) -> str | None:
        return self.tokens[self.position][1] if self.position < len(self.tokens) else None

    def take(self, expected: str | None = None) -> tuple[str, str]:
        if self.position >= len(self.tokens) or (expected and self.tokens[self.position][1] != expected):
            raise Refused(f"{self.text}: expected {expected or 'more'} here")
        self.position += 1
        return self.tokens[self.position - 1]

    def level(self, index: int, depth: int) -> Tree:
        if depth > MAX_DEPTH:
            raise Refused(f"{self.text}: nested deeper than {MAX_DEPTH}")
        if index == len(LEVELS):
            return self.unary(depth)
        left = self.level(index + 1, depth + 1)
        while self.peek() in LEVELS[index]:
            operator = self.take()[1]
            left = (operator, left, self.level(index + 1, depth + 1))
        return left

    def unary(self, depth: int) -> Tree:
        if depth > MAX_DEPTH:
            raise Refused(f"{self.text}: nested deeper than {MAX_DEPTH}")
        if self.peek() in ("-", "+", "NOT"):
            sign = self.take()[1]
            operand = self.unary(depth + 1)
            return operand if sign == "+" else ("neg" if sign == "-" else "not", operand)
        return self.primary(depth)

    def primary(self, depth: int) -> Tree:
        kind, value = self.take()
        if kind == "number":
            return ("number", plain_decimal("", value))     # at most MAX_DIGITS digits
        if value == "(":
            inner = self.level(0, depth + 1)
            self.take(")")
            return inner
        if kind != "name":
            raise Refused(f"{self.text}: {value!r} where a value belongs")
        if self.peek() == "[":
            raise Refused(f"{value}[…]: an indexed or indirect parameter names its value at run time")
        if self.peek() == "(":
            return ("call", value, self.arguments(depth))
        return ("name", value)

    def arguments(self, depth: int) -> tuple[Tree, ...]:
        self.take("(")
        found = [self.level(0, depth + 1)]
        while self.peek() == ",":
            self.take(",")
            found.append(self.level(0, depth + 1))
        self.take(")")
        return tuple(found)


def _value(tree: Tree, values: dict[str, float]) -> float:
    kind = tree[0]
    if kind == "number":
        return float(tree[1])
    if kind == "name":
        return _named(tree[1], values)
    if kind == "call":
        return _call(tree[1], [_value(argument, values) for argument in tree[2]])
    if kind == "neg":
        return -_value(tree[1], values)
    if kind == "not":
        return float(not _value(tree[1], values))
    operator = next(level[kind] for level in LEVELS if kind in level)
    return operator(_value(tree[1], values), _value(tree[2], values))


def _named(name: str, values: dict[str, float]) -> float:
    if name in values:
        return values[name]
    if name in CONSTANTS:
        return CONSTANTS[name]
    if name.startswith("$"):
        raise Refused(f"{name}: a system variable has its value only on the control")
    if re.fullmatch(r"R\d+", name):
        raise Refused(f"{name} is read before the program sets it: its value is whatever the control holds")
    raise Refused(f"{name} is neither a DEF variable of the program nor an R-parameter it has set")


def _call(name: str, arguments: list[float]) -> float:
    if name in ("IC", "AC", "ACP", "ACN", "DC"):
        raise Refused(f"{name}(…) inside arithmetic: the verifier reads it only as a whole word value")
    if name not in FUNCTIONS:
        raise Refused(f"{name}(…) is not an arithmetic function the verifier evaluates "
                      f"(it has {', '.join(sorted(FUNCTIONS))})")
    count, function = FUNCTIONS[name]
    if len(arguments) != count:
        raise Refused(f"{name} takes {count} argument{'s' if count > 1 else ''}, not {len(arguments)}")
    try:
        return float(function(*arguments))
    except (ValueError, OverflowError):
        raise Refused(f"{name}({', '.join(f'{a:g}' for a in arguments)}) has no value") from None
