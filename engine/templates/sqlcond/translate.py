"""sqlglot tree -> Python ``ast.expr`` calling the ``_sql_*`` helpers (runs once per template).

Each supported sqlglot node class has a handler ``(node, lazy) -> ast.expr`` in
``_HANDLERS``, with the argument keys it consumes; a node with any other operand
is rejected.  ``lazy`` is true for operands a lazy helper may never evaluate:
their calls are wrapped in ``_sql_defer`` thunks.
"""

from __future__ import annotations

import ast
import keyword
from collections.abc import Callable
from typing import NoReturn

from sqlglot import exp

from ...errors import EngineError
from .parse import NOT_PARSED, parse, reject_subqueries, render

_RESERVED_PREFIX = "_sql_"
_SUPPORTED_FUNCTIONS = (
    "ABS, CEIL, CEILING, COALESCE, FLOOR, GREATEST, LEAST, MOD, NULLIF, POW, POWER, ROUND, SQRT"
)


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
    return not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "_sql_defer")


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
                f"qualified name {render(node)} is not allowed in condition; use the parameter name alone"
            )
    if not isinstance(node.this, exp.Identifier):
        raise EngineError(f"{render(node)} is not allowed in condition; name a parameter")
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
    value = operand.value if isinstance(operand, ast.Constant) else None
    if isinstance(value, (int, float)) and type(value) in (int, float):
        return ast.Constant(-value)
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
        raise EngineError(f"unsupported IS test in condition: {render(node)}")
    return _negated(node, lazy, _strict_call(helper, [node.this], lazy))


def _between(node, lazy):
    helper = "_sql_between_symmetric" if node.args.get("symmetric") else "_sql_between"
    return _strict_call(helper, [node.this, node.args["low"], node.args["high"]], lazy)


def _in(node, lazy):
    if not node.expressions:
        raise EngineError(f"IN needs a parenthesised list of values: {render(node)}")
    return _strict_call("_sql_in", [node.this, *node.expressions], lazy)


def _like(node, lazy, escape=None):
    helper = "_sql_ilike" if isinstance(node, exp.ILike) else "_sql_like"
    args = [_tr(node.this, lazy), _tr(node.expression, lazy)]
    if escape is not None:
        args.append(ast.Constant(escape))
    return _negated(node, lazy, _call(helper, args, lazy))


def _escape(node, lazy):
    like, escape = node.this, node.expression
    if not isinstance(like, (exp.Like, exp.ILike)):
        raise EngineError(f"ESCAPE is only supported after LIKE or ILIKE: {render(node)}")
    if not (isinstance(escape, exp.Literal) and escape.is_string and len(escape.this) <= 1):
        raise EngineError(f"ESCAPE needs a one-character string literal: {render(node)}")
    _check_args(like, _HANDLERS[type(like)][1])
    return _like(like, lazy, escape.this)


def _case(node, lazy):
    subject = node.this
    parts = []
    for branch in node.args.get("ifs") or []:
        if not isinstance(branch, exp.If) or branch.args.get("false") is not None:
            raise EngineError(f"unsupported CASE branch in condition: {render(branch)}")
        test = branch.this
        if subject is not None:  # simple CASE: compare the subject with each WHEN value
            if not isinstance(subject, (exp.Column, exp.Literal, exp.Boolean, exp.Null)):
                # the subject is repeated in every WHEN: nested, it would grow exponentially
                raise EngineError(f"CASE {render(subject)} WHEN …: the subject of a simple CASE must be "
                                  "a name or a constant; write CASE WHEN … THEN … instead")
            test = exp.EQ(this=subject.copy(), expression=branch.this.copy())
        parts += [test, branch.args["true"]]
    if not parts:
        raise EngineError(f"CASE needs at least one WHEN branch: {render(node)}")
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
    exp.Like: (_like, _OPERANDS),
    exp.ILike: (_like, _OPERANDS),
    exp.Escape: (_escape, _OPERANDS),
    exp.Case: (_case, frozenset({"this", "ifs", "default"})),
    exp.Coalesce: (_coalesce, frozenset({"this", "expressions"})),
    exp.Round: (_round, frozenset({"this", "decimals"})),
    **{cls: (_binary(helper), _OPERANDS) for cls, helper in _BINARY.items()},
    **{cls: (_unary(helper), frozenset({"this"})) for cls, helper in _UNARY.items()},
    **{cls: (_variadic(helper), frozenset({"this", "expressions"}))
       for cls, helper in _VARIADIC.items()},
}


def _reject(node) -> NoReturn:
    if isinstance(node, exp.Anonymous):
        name = node.name
    elif isinstance(node, exp.Cast):
        raise EngineError(f"type casts are not supported in condition: {render(node)}")
    elif isinstance(node, exp.Func):
        name = node.sql_name()
    elif isinstance(node, exp.Star):
        raise EngineError("'*' is not allowed in condition")
    else:
        raise EngineError(f"unsupported SQL in condition: {render(node)} ({type(node).__name__})")
    raise EngineError(f"unknown SQL function {name} in condition; supported: {_SUPPORTED_FUNCTIONS}")


def _check_args(node, consumed):
    for key, value in node.args.items():
        operand = isinstance(value, exp.Expression) or (isinstance(value, list) and value)
        if operand and key not in consumed:
            raise EngineError(f"unsupported SQL in condition: {render(node)} (part {key!r})")


def _tr(node, lazy):
    entry = _HANDLERS.get(type(node))
    if entry is None:
        _reject(node)
    handler, consumed = entry
    _check_args(node, consumed)
    return handler(node, lazy)


def translate(text: str) -> ast.expr:
    """Translate a SQL condition into a Python expression tree (see the package docs)."""
    if not isinstance(text, str) or not text.strip():
        raise EngineError(f"{NOT_PARSED}: empty condition")
    try:
        tree = parse(text)
        reject_subqueries(tree)
        node = _tr(tree, False)
    except RecursionError:
        raise EngineError("condition is nested too deeply") from None
    return ast.fix_missing_locations(node)
