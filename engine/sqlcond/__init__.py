"""Translate a SQL condition (PostgreSQL flavour) into a Python ``ast.expr``.

Template rows hold conditions that users may type either as Python or "the way a
DBA writes SQL", e.g. ``ctr_px = 'T' AND shift <> 0``.  The expression compiler
tries Python first; when the text is not a Python expression it calls
:func:`translate`, validates the returned node and compiles it.  The compiled
code is evaluated with :data:`SQL_RUNTIME` and the template parameters as names.

Public surface
--------------
``SQL_RUNTIME``
    dict of the helper functions the translated tree calls; every name starts
    with ``_sql_``.  ``_sql_truth(x)`` turns a three-valued result into a bool
    (True only for True); the translated tree itself never coerces.
``translate(text) -> ast.expr``
    raises :class:`engine.errors.EngineError` with a one-line message.

The returned tree consists only of ``ast.Call`` (``func`` is an ``ast.Name`` of
a ``_sql_*`` helper, positional arguments only), ``ast.Name`` (parameter
references, Load context, spelled exactly as typed) and ``ast.Constant``
(int, float, str, bool, None).  Every ``ast.Name`` that is not in a ``func``
position is a parameter reference.

Supported SQL
-------------
* literals: ``'text'`` (``''`` escapes), integers, decimals (as float),
  ``TRUE``, ``FALSE``, ``NULL``; identifiers, unquoted or ``"double quoted"``,
  that are Python identifiers (not keywords, not starting with ``_sql_``).
* comparisons ``= <> != < <= > >=``, ``IS [NOT] NULL``, ``ISNULL``,
  ``NOTNULL``, ``IS [NOT] TRUE``, ``IS [NOT] FALSE``, ``IS [NOT] UNKNOWN``,
  ``IS [NOT] DISTINCT FROM``, ``[NOT] BETWEEN [SYMMETRIC] a AND b``,
  ``[NOT] IN (list)``, ``[NOT] LIKE`` / ``[NOT] ILIKE`` (``%``, ``_``,
  backslash escape or ``ESCAPE 'c'``).
* ``AND``, ``OR``, ``NOT`` with SQL three-valued logic.
* ``+ - * / %``, unary ``-``, ``^`` (power), ``||`` (text concatenation).
* ``CASE [x] WHEN ... THEN ... [ELSE ...] END``, ``COALESCE``, ``NULLIF``,
  ``ABS``, ``CEIL``/``CEILING``, ``FLOOR``, ``ROUND(x[, n])``, ``SQRT``,
  ``POWER``/``POW``, ``MOD``, ``LEAST``, ``GREATEST``.

Semantics
---------
* NULL is Python None.  Comparisons, arithmetic, ``||``, LIKE and IN follow
  SQL NULL rules; AND/OR/NOT use the three-valued truth table.
* AND, OR, CASE and COALESCE evaluate their operands left to right and stop as
  soon as the result is known (as PostgreSQL does in practice), so
  ``b <> 0 AND a / b > 1`` and ``CASE WHEN b = 0 THEN 0 ELSE a / b END`` do
  not divide by zero.  Operands after the first that might raise are passed to
  the helper as thunks built by ``_sql_defer``.
* No implicit casts: text never equals a number and a boolean never equals a
  number (the result is FALSE); ordering comparisons between them raise
  TypeError.  AND/OR/NOT and CASE WHEN conditions need boolean operands,
  arithmetic needs numbers (booleans are not numbers), otherwise TypeError.
* ``/`` on two integers truncates toward zero (``-7 / 2`` is ``-3``); with a
  float or Decimal operand it is ordinary division.  ``%`` takes the sign of
  the dividend.  Division or modulo by zero raises
  ``ZeroDivisionError("division by zero")``.
* ``^``/``POWER`` return float; ``ROUND`` rounds half away from zero (like
  PostgreSQL's numeric), returning the argument's type.
* ``x || y`` needs at least one text operand; the other is rendered as text
  (booleans as ``true``/``false``).
* Results are bounded like the rest of the expression engine: ``+ - *`` raise
  OverflowError beyond MAX_INT_BITS, ``||`` raises ValueError beyond
  MAX_TEXT_LENGTH characters.

Not supported (rejected with EngineError): subqueries, ``*``, qualified names
(``t.x``), casts, arrays, JSON operators, parameters/placeholders, any other
function, more than one statement.
"""

from __future__ import annotations

import ast
import functools
import keyword
import math
import numbers
import re
from collections.abc import Callable
from decimal import ROUND_CEILING, ROUND_FLOOR, ROUND_HALF_UP, Context, Decimal

import sqlglot
from sqlglot import exp
from sqlglot.errors import ParseError, SqlglotError, TokenError
from sqlglot.tokens import TokenType

from ..errors import EngineError

__all__ = ["SQL_RUNTIME", "translate"]


# --------------------------------------------------------------------------
# Runtime helpers (run on every evaluation; keep them simple)
# --------------------------------------------------------------------------

MAX_TEXT_LENGTH = 1 << 16  # characters of a string built by ||
MAX_INT_BITS = 4_096  # bits of an integer built by + - *

_KINDS = {bool: "boolean", int: "number", float: "number", Decimal: "number", str: "text"}


def _kind(value):
    kind = _KINDS.get(type(value))
    if kind is not None:
        return kind
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, numbers.Number):
        return "number"
    if isinstance(value, str):
        return "text"
    return type(value).__name__


def _describe(value):
    return f"{_kind(value)} {value!r}"


def _same_number_type(a, b):
    """Mixed Decimal/float operands are compared and combined as floats."""
    if type(a) is not type(b) and (isinstance(a, float) or isinstance(b, float)):
        return float(a), float(b)
    return a, b


def _comparable(a, b, op):
    kind_a, kind_b = _kind(a), _kind(b)
    if kind_a != kind_b:
        raise TypeError(f"cannot compare {_describe(a)} with {_describe(b)} using {op}")
    if kind_a == "number":
        return _same_number_type(a, b)
    return a, b


def _numbers(a, b, op):
    if _kind(a) != "number":
        raise TypeError(f"operator {op} needs numbers, got {_describe(a)}")
    if _kind(b) != "number":
        raise TypeError(f"operator {op} needs numbers, got {_describe(b)}")
    return _same_number_type(a, b)


def _number(value, name):
    if _kind(value) != "number":
        raise TypeError(f"{name} needs a number, got {_describe(value)}")
    return value


class _Deferred:
    """An operand that is evaluated only when a lazy helper asks for it."""

    __slots__ = ("fn", "args", "strict")

    def __init__(self, fn, args, strict):
        self.fn = fn
        self.args = args
        self.strict = strict

    def force(self):
        if self.strict:
            return self.fn(*[_force(arg) for arg in self.args])
        return self.fn(*self.args)


def _force(value):
    return value.force() if type(value) is _Deferred else value


def _boolean(value, op):
    value = _force(value)
    if value is None or value is True or value is False:
        return value
    raise TypeError(f"argument of {op} must be boolean, got {_describe(value)}")


def _sql_truth(value):
    """Final verdict of a condition: only TRUE counts, NULL is false."""
    return value is True


def _sql_defer(name, *args):
    fn, strict = _DEFERRABLE[name]
    return _Deferred(fn, args, strict)


def _sql_and(*args):
    result = True
    for arg in args:
        value = _boolean(arg, "AND")
        if value is False:
            return False
        if value is None:
            result = None
    return result


def _sql_or(*args):
    result = False
    for arg in args:
        value = _boolean(arg, "OR")
        if value is True:
            return True
        if value is None:
            result = None
    return result


def _sql_not(value):
    value = _boolean(value, "NOT")
    return None if value is None else not value


def _sql_eq(a, b):
    if a is None or b is None:
        return None
    kind = _kind(a)
    if kind != _kind(b):
        return False
    if kind == "number":
        a, b = _same_number_type(a, b)
    return a == b


def _sql_ne(a, b):
    result = _sql_eq(a, b)
    return None if result is None else not result


def _sql_lt(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, "<")
    return a < b


def _sql_le(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, "<=")
    return a <= b


def _sql_gt(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, ">")
    return a > b


def _sql_ge(a, b):
    if a is None or b is None:
        return None
    a, b = _comparable(a, b, ">=")
    return a >= b


def _sql_is_null(value):
    return value is None


def _sql_is_true(value):
    return value is True


def _sql_is_false(value):
    return value is False


def _sql_distinct(a, b):
    """a IS DISTINCT FROM b: like <>, but NULL is a comparable value."""
    if a is None or b is None:
        return (a is None) is not (b is None)
    return not _sql_eq(a, b)


def _sql_not_distinct(a, b):
    return not _sql_distinct(a, b)


def _sql_between(value, low, high):
    return _sql_and(_sql_ge(value, low), _sql_le(value, high))


def _sql_between_symmetric(value, low, high):
    return _sql_or(_sql_between(value, low, high), _sql_between(value, high, low))


def _sql_in(value, *items):
    if value is None:
        return None
    result = False
    for item in items:
        equal = _sql_eq(value, item)
        if equal:
            return True
        if equal is None:
            result = None
    return result


class _LikePattern:
    """A LIKE pattern split at its ``%`` wildcards into fixed-length segments.

    Matching the first segment at the start, the last at the end and each middle
    segment at its leftmost position in between is exact for such patterns and
    takes O(len(value) * len(pattern)), unlike one backtracking regex with
    several ``.*`` (which can take exponential time).
    """

    __slots__ = ("whole", "first", "middle", "last", "last_length")

    def __init__(self, segments, flags):
        compiled = [re.compile("".join(parts), flags | re.DOTALL) for parts in segments]
        self.whole = len(compiled) == 1  # no % at all
        self.first, self.middle, self.last = compiled[0], compiled[1:-1], compiled[-1]
        self.last_length = len(segments[-1])

    def matches(self, value):
        if self.whole:
            return self.first.fullmatch(value) is not None
        found = self.first.match(value)
        if found is None:
            return False
        position, tail = found.end(), len(value) - self.last_length
        for segment in self.middle:
            found = segment.search(value, position, tail)
            if found is None:
                return False
            position = found.end()
        return position <= tail and self.last.fullmatch(value, tail) is not None


@functools.lru_cache(maxsize=512)
def _like_pattern(pattern, escape, flags):
    if len(escape) > 1:
        raise ValueError(f"invalid escape string {escape!r}: use one character or ''")
    segments = [[]]  # each segment: regex parts, one per character matched
    chars = iter(pattern)
    for char in chars:
        if escape and char == escape:
            literal = next(chars, None)
            if literal is None:
                raise ValueError("LIKE pattern must not end with escape character")
            segments[-1].append(re.escape(literal))
        elif char == "%":
            segments.append([])
        elif char == "_":
            segments[-1].append(".")
        else:
            segments[-1].append(re.escape(char))
    return _LikePattern(segments, flags)


def _like(value, pattern, escape, flags, op):
    if value is None or pattern is None or escape is None:
        return None
    for operand in (value, pattern, escape):
        if not isinstance(operand, str):
            raise TypeError(f"operator {op} needs text, got {_describe(operand)}")
    return _like_pattern(pattern, escape, flags).matches(value)


def _sql_like(value, pattern, escape="\\"):
    return _like(value, pattern, escape, 0, "LIKE")


def _sql_ilike(value, pattern, escape="\\"):
    return _like(value, pattern, escape, re.IGNORECASE, "ILIKE")


def _text(value):
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _sql_concat(a, b):
    if a is None or b is None:
        return None
    if not isinstance(a, str) and not isinstance(b, str):
        raise TypeError(f"operator || needs a text operand, got {_describe(a)} and {_describe(b)}")
    text = _text(a) + _text(b)
    if len(text) > MAX_TEXT_LENGTH:
        raise ValueError(f"string too long (more than {MAX_TEXT_LENGTH} characters)")
    return text


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
    if exact.as_tuple().exponent >= -digits:
        return value  # nothing to round away
    rounded = exact.quantize(Decimal(1).scaleb(-digits), ROUND_HALF_UP, _ROUND_CONTEXT)
    return type(value)(rounded) if isinstance(value, (int, float)) else rounded


def _sql_least(*args):
    best = None
    for value in args:
        if value is not None and (best is None or _sql_lt(value, best)):
            best = value
    return best


def _sql_greatest(*args):
    best = None
    for value in args:
        if value is not None and (best is None or _sql_gt(value, best)):
            best = value
    return best


def _sql_nullif(a, b):
    return None if _sql_eq(a, b) is True else a


def _sql_coalesce(*args):
    for arg in args:
        value = _force(arg)
        if value is not None:
            return value
    return None


def _sql_case(*args):
    """Arguments: condition, result, condition, result, ..., else-result."""
    last = len(args) - 1
    for index in range(0, last, 2):
        if _boolean(args[index], "CASE WHEN") is True:
            return _force(args[index + 1])
    return _force(args[last])


SQL_RUNTIME: dict[str, Callable] = {
    name: value for name, value in globals().items() if name.startswith("_sql_") and callable(value)
}

_LAZY = frozenset({"_sql_and", "_sql_or", "_sql_case", "_sql_coalesce"})
_DEFERRABLE = {
    name: (fn, name not in _LAZY) for name, fn in SQL_RUNTIME.items() if name != "_sql_defer"
}


# --------------------------------------------------------------------------
# Translation (runs once per template)
# --------------------------------------------------------------------------

_NOT_PARSED = "not a Python or SQL expression"
_RESERVED_PREFIX = "_sql_"
_SUPPORTED_FUNCTIONS = (
    "ABS, CEIL, CEILING, COALESCE, FLOOR, GREATEST, LEAST, MOD, NULLIF, POW, POWER, ROUND, SQRT"
)


def _short(text, limit=60):
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _render(node):
    try:
        return _short(node.sql(dialect="postgres"))
    except Exception:  # noqa: BLE001 - only used for messages
        return type(node).__name__


def _name(identifier):
    name = identifier.this
    if not isinstance(name, str) or not name.isidentifier() or keyword.iskeyword(name):
        raise EngineError(
            f'identifier "{name}" in condition is not a valid parameter name; use a Python identifier'
        )
    if name.startswith(_RESERVED_PREFIX):
        raise EngineError(f"identifier {name} in condition uses the reserved prefix {_RESERVED_PREFIX}")
    return ast.Name(id=name, ctx=ast.Load())


# Helpers that cannot raise and are cheap: in a lazy position they are called
# directly instead of being wrapped in a thunk, when their arguments are too.
_CANNOT_RAISE = frozenset({
    "_sql_eq", "_sql_ne", "_sql_is_null", "_sql_is_true", "_sql_is_false",
    "_sql_distinct", "_sql_not_distinct", "_sql_in", "_sql_nullif",
})


def _is_direct(node):
    """A leaf, or a direct call (only ever made to a helper that cannot raise)."""
    return not isinstance(node, ast.Call) or node.func.id != "_sql_defer"


def _call(helper, args, lazy):
    if lazy and not (helper in _CANNOT_RAISE and all(_is_direct(arg) for arg in args)):
        return ast.Call(
            func=ast.Name(id="_sql_defer", ctx=ast.Load()),
            args=[ast.Constant(helper), *args],
            keywords=[],
        )
    return ast.Call(func=ast.Name(id=helper, ctx=ast.Load()), args=list(args), keywords=[])


def _lazy_call(helper, nodes, lazy):
    """Call a lazy helper: the first operand as usual, the rest deferred."""
    args = [_tr(nodes[0], lazy)] + [_tr(node, True) for node in nodes[1:]]
    return _call(helper, args, lazy)


def _strict_call(helper, nodes, lazy):
    return _call(helper, [_tr(node, lazy) for node in nodes], lazy)


def _negated(node, lazy, result):
    return _call("_sql_not", [result], lazy) if node.args.get("negate") else result


def _flatten(node, cls):
    if isinstance(node, cls):
        return _flatten(node.this, cls) + _flatten(node.expression, cls)
    return [node]


# ---- handlers: (node, lazy) -> ast.expr ----


def _column(node, lazy):
    for part in ("table", "db", "catalog"):
        if node.args.get(part):
            raise EngineError(
                f"qualified name {_render(node)} is not allowed in condition; use the parameter name alone"
            )
    if not isinstance(node.this, exp.Identifier):
        raise EngineError(f"{_render(node)} is not allowed in condition; name a parameter")
    return _name(node.this)


def _literal(node, lazy):
    if node.is_string:
        return ast.Constant(node.this)
    text = node.this
    try:
        return ast.Constant(int(text) if text.isdigit() else float(text))
    except ValueError:
        raise EngineError(f"bad number {text!r} in condition") from None


def _boolean_literal(node, lazy):
    return ast.Constant(bool(node.this))


def _null(node, lazy):
    return ast.Constant(None)


def _paren(node, lazy):
    return _tr(node.this, lazy)


def _neg(node, lazy):
    operand = _tr(node.this, lazy)
    if isinstance(operand, ast.Constant) and type(operand.value) in (int, float):
        return ast.Constant(-operand.value)
    return _call("_sql_neg", [operand], lazy)


def _and(node, lazy):
    return _lazy_call("_sql_and", _flatten(node, exp.And), lazy)


def _or(node, lazy):
    return _lazy_call("_sql_or", _flatten(node, exp.Or), lazy)


def _binary(helper):
    def handler(node, lazy):
        return _strict_call(helper, [node.this, node.expression], lazy)

    return handler


def _unary(helper):
    def handler(node, lazy):
        return _strict_call(helper, [node.this], lazy)

    return handler


def _variadic(helper):
    def handler(node, lazy):
        return _strict_call(helper, [node.this, *node.expressions], lazy)

    return handler


def _is(node, lazy):
    target = node.expression
    if isinstance(target, exp.Null):
        helper = "_sql_is_null"
    elif isinstance(target, exp.Boolean):
        helper = "_sql_is_true" if target.this else "_sql_is_false"
    else:
        raise EngineError(f"unsupported IS test in condition: {_render(node)}")
    return _negated(node, lazy, _strict_call(helper, [node.this], lazy))


def _between(node, lazy):
    helper = "_sql_between_symmetric" if node.args.get("symmetric") else "_sql_between"
    return _strict_call(helper, [node.this, node.args["low"], node.args["high"]], lazy)


def _in(node, lazy):
    if not node.expressions:
        raise EngineError(f"IN needs a parenthesised list of values: {_render(node)}")
    return _strict_call("_sql_in", [node.this, *node.expressions], lazy)


def _like_call(node, lazy, escape=None):
    helper = "_sql_ilike" if isinstance(node, exp.ILike) else "_sql_like"
    args = [_tr(node.this, lazy), _tr(node.expression, lazy)]
    if escape is not None:
        args.append(ast.Constant(escape))
    return _negated(node, lazy, _call(helper, args, lazy))


def _like_handler(node, lazy):
    return _like_call(node, lazy)


def _escape(node, lazy):
    like, escape = node.this, node.expression
    if not isinstance(like, (exp.Like, exp.ILike)):
        raise EngineError(f"ESCAPE is only supported after LIKE or ILIKE: {_render(node)}")
    if not (isinstance(escape, exp.Literal) and escape.is_string and len(escape.this) <= 1):
        raise EngineError(f"ESCAPE needs a one-character string literal: {_render(node)}")
    _check_args(like, _HANDLERS[type(like)][1])
    return _like_call(like, lazy, escape.this)


def _case(node, lazy):
    subject = node.this
    parts = []
    for branch in node.args.get("ifs") or []:
        if not isinstance(branch, exp.If) or branch.args.get("false") is not None:
            raise EngineError(f"unsupported CASE branch in condition: {_render(branch)}")
        test = branch.this
        if subject is not None:  # simple CASE: compare the subject with each WHEN value
            test = exp.EQ(this=subject.copy(), expression=branch.this.copy())
        parts += [test, branch.args["true"]]
    if not parts:
        raise EngineError(f"CASE needs at least one WHEN branch: {_render(node)}")
    parts.append(node.args.get("default") or exp.Null())
    return _lazy_call("_sql_case", parts, lazy)


def _coalesce(node, lazy):
    return _lazy_call("_sql_coalesce", [node.this, *node.expressions], lazy)


def _round(node, lazy):
    digits = node.args.get("decimals")
    return _strict_call("_sql_round", [node.this] + ([digits] if digits is not None else []), lazy)


_BINARY = {
    exp.EQ: "_sql_eq",
    exp.NEQ: "_sql_ne",
    exp.LT: "_sql_lt",
    exp.LTE: "_sql_le",
    exp.GT: "_sql_gt",
    exp.GTE: "_sql_ge",
    exp.NullSafeEQ: "_sql_not_distinct",
    exp.NullSafeNEQ: "_sql_distinct",
    exp.Add: "_sql_add",
    exp.Sub: "_sql_sub",
    exp.Mul: "_sql_mul",
    exp.Div: "_sql_div",
    exp.Mod: "_sql_mod",
    exp.Pow: "_sql_power",
    exp.DPipe: "_sql_concat",
    exp.Nullif: "_sql_nullif",
}
_UNARY = {
    exp.Not: "_sql_not",
    exp.Abs: "_sql_abs",
    exp.Sqrt: "_sql_sqrt",
    exp.Floor: "_sql_floor",
    exp.Ceil: "_sql_ceil",
}
_VARIADIC = {exp.Least: "_sql_least", exp.Greatest: "_sql_greatest"}

_OPERANDS = frozenset({"this", "expression"})

# sqlglot expression class -> (handler, argument keys the handler consumes)
_HANDLERS: dict[type, tuple[Callable, frozenset]] = {
    exp.Column: (_column, frozenset({"this", "table", "db", "catalog"})),
    exp.Literal: (_literal, frozenset({"this"})),
    exp.Boolean: (_boolean_literal, frozenset({"this"})),
    exp.Null: (_null, frozenset()),
    exp.Paren: (_paren, frozenset({"this"})),
    exp.Neg: (_neg, frozenset({"this"})),
    exp.And: (_and, _OPERANDS),
    exp.Or: (_or, _OPERANDS),
    exp.Is: (_is, _OPERANDS),
    exp.Between: (_between, frozenset({"this", "low", "high"})),
    exp.In: (_in, frozenset({"this", "expressions"})),
    exp.Like: (_like_handler, _OPERANDS),
    exp.ILike: (_like_handler, _OPERANDS),
    exp.Escape: (_escape, _OPERANDS),
    exp.Case: (_case, frozenset({"this", "ifs", "default"})),
    exp.Coalesce: (_coalesce, frozenset({"this", "expressions"})),
    exp.Round: (_round, frozenset({"this", "decimals"})),
    **{cls: (_binary(helper), _OPERANDS) for cls, helper in _BINARY.items()},
    **{cls: (_unary(helper), frozenset({"this"})) for cls, helper in _UNARY.items()},
    **{cls: (_variadic(helper), frozenset({"this", "expressions"}))
       for cls, helper in _VARIADIC.items()},
}


def _reject(node):
    if isinstance(node, exp.Anonymous):
        name = node.name
    elif isinstance(node, exp.Cast):
        raise EngineError(f"type casts are not supported in condition: {_render(node)}")
    elif isinstance(node, exp.Func):
        name = node.sql_name()
    elif isinstance(node, exp.Star):
        raise EngineError("'*' is not allowed in condition")
    else:
        raise EngineError(f"unsupported SQL in condition: {_render(node)} ({type(node).__name__})")
    raise EngineError(f"unknown SQL function {name} in condition; supported: {_SUPPORTED_FUNCTIONS}")


def _check_args(node, consumed):
    for key, value in node.args.items():
        operand = isinstance(value, exp.Expression) or (isinstance(value, list) and value)
        if operand and key not in consumed:
            raise EngineError(f"unsupported SQL in condition: {_render(node)} (part {key!r})")


def _tr(node, lazy):
    entry = _HANDLERS.get(type(node))
    if entry is None:
        _reject(node)
    handler, consumed = entry
    _check_args(node, consumed)
    return handler(node, lazy)


# ---- parsing ----


def _column_of(text, offset):
    return offset - text.rfind("\n", 0, offset)


def _parse_error_message(error):
    details = error.errors[0] if getattr(error, "errors", None) else None
    if not details:
        if str(error).startswith("No expression was parsed"):
            return "empty condition"
        return _short(str(error).splitlines()[0] if str(error) else type(error).__name__, 100)
    token = _short(details.get("highlight") or "", 30)
    column = max(1, (details.get("col") or 1) - len(details.get("highlight") or "") + 1)
    line = details.get("line") or 1
    where = f"at column {column}" if line <= 1 else f"at line {line} column {column}"
    description = details.get("description") or ""
    if description.startswith("Invalid expression / Unexpected token"):
        return f"unexpected token {token!r} {where}"
    if description.startswith("Required keyword"):
        return f"incomplete expression near {token!r} {where}"
    if description.startswith("Expecting"):
        return f"{description.lower()} near {token!r} {where}"
    return f"{_short(description, 80)} near {token!r} {where}"


def _parse(text):
    dialect = sqlglot.Dialect.get_or_raise("postgres")
    try:
        tokens = dialect.tokenize(text)
    except TokenError as error:
        raise EngineError(f"{_NOT_PARSED}: cannot split into SQL tokens ({_short(error, 80)})") from None
    for token in tokens:
        if token.token_type == TokenType.SEMICOLON:
            column = _column_of(text, token.start)
            raise EngineError(f"{_NOT_PARSED}: ';' at column {column}; a condition is a single expression")
    try:
        return sqlglot.parse_one(text, read=dialect, into=exp.Condition)
    except ParseError as error:
        raise EngineError(f"{_NOT_PARSED}: {_parse_error_message(error)}") from None
    except SqlglotError as error:
        raise EngineError(f"{_NOT_PARSED}: {_short(str(error), 80)}") from None


def _reject_subqueries(tree):
    for node in tree.walk():
        if isinstance(node, (exp.Query, exp.Subquery, exp.Exists)):
            raise EngineError(f"subquery not allowed in condition: {_render(node)}")


def translate(text: str) -> ast.expr:
    """Translate a SQL condition into a Python expression tree (see module docs)."""
    if not isinstance(text, str) or not text.strip():
        raise EngineError(f"{_NOT_PARSED}: empty condition")
    try:
        tree = _parse(text)
        _reject_subqueries(tree)
        node = _tr(tree, False)
    except RecursionError:
        raise EngineError("condition is nested too deeply") from None
    return ast.fix_missing_locations(node)
