"""asteval, the run-time evaluator of every template expression (design notes §4).

One locked-down asteval Interpreter per compiled template: `minimal`, no numpy, only the
nodes a checked expression can contain, and a symbol table that holds our functions,
constants and guards and the job's names, nothing of Python's builtins. It runs the guarded
trees the gate produced (engine.templates.expressions), parsed once per template version.
"""
from __future__ import annotations

import ast
import threading

from ..errors import EngineError
from .asteval_import import ALL_NODES, Interpreter
from .budget import Budget, paid, running, spending
from .functions import CONSTANTS, FUNCTIONS, NC_NUMBER_SPEC, nc_number
from .guards import (
    built,
    check_printable,
    guard_size,
    safe_add,
    safe_format,
    safe_lshift,
    safe_mod,
    safe_mult,
    safe_pow,
)

# The asteval node handlers a checked expression needs; every other node is switched off.
NODES = ("expression", "binop", "unaryop", "boolop", "compare", "ifexp", "call", "name", "constant",
         "joinedstr", "formattedvalue", "tuple", "list", "subscript", "slice", "index")
GUARDS = {"_safe_pow": safe_pow, "_safe_mult": safe_mult, "_safe_add": safe_add, "_safe_lshift": safe_lshift,
          "_safe_mod": safe_mod, "_safe_format": safe_format, "_guard": guard_size, "_built": built}
MAX_MESSAGE = 300   # characters of a failure's message (asteval's own repeats the arguments)


def base_symbols(uses_sql: bool) -> dict:
    """What every expression may name besides the job's parameters and intermediates."""
    symbols = {**FUNCTIONS, **CONSTANTS, **GUARDS}
    if uses_sql:
        from .sqlcond.runtime import SQL_RUNTIME  # the helpers translated SQL conditions call

        symbols.update(SQL_RUNTIME)
    return symbols


class EvaluationError(EngineError):
    """An expression failed under asteval: the message says how, in one line."""


class Evaluator:
    """A locked-down asteval Interpreter that evaluates one checked tree at a time in a scope."""

    def __init__(self):
        config = {node: node in NODES for node in ALL_NODES}
        self.interpreter = Interpreter(symtable={}, minimal=True, use_numpy=False, config=config)
        self.interpreter.set_nodehandler("formattedvalue", _formatted_value(self.interpreter))
        self.interpreter.set_nodehandler("call", _call(self.interpreter))

    def evaluate(self, tree: ast.expr, text: str, scope: dict):
        """The value of `tree` (the checked form of `text`) with `scope` as asteval's symbol table."""
        if type(tree) is ast.Constant:   # a line written out (most rows of an imported program)
            return tree.value
        interpreter = self.interpreter
        interpreter.symtable = scope
        interpreter.error, interpreter.error_msg, interpreter.expr = [], None, text
        interpreter.retval = interpreter._interrupt = None
        try:
            return interpreter.run(tree)
        except Exception as error:   # asteval re-raises the expression's own failure
            raise EvaluationError(_problem(interpreter.error, error)) from None

    def forget(self) -> None:
        """Drop the last job's scope and failures (a finished run keeps nothing alive)."""
        interpreter = self.interpreter
        interpreter.symtable, interpreter.error, interpreter.error_msg, interpreter.expr = {}, [], None, None


_ALIGNMENTS = ("<", ">", "=", "^")   # `{x:~>9}` is Python's: fill `~`, aligned right


def _formatted_value(interpreter):
    """The f-string field handler: `format(value, spec)`, or nc_number for a spec `~style` (no
    format spec of Python's starts with `~` not followed by an alignment). asteval's own goes through
    string.Formatter to stop `{0.attr}` lookups in a format string, which a checked expression
    cannot contain (its specs are plain and bounded, conversions are refused by the gate), at
    a third of the time an NC line takes."""
    def on_formattedvalue(node):
        spec = "" if node.format_spec is None else interpreter.run(node.format_spec)
        value = interpreter.run(node.value)
        check_printable(value)   # before printing it: a field of a huge value is refused, not rendered
        if spec[:1] == NC_NUMBER_SPEC and spec[1:2] not in _ALIGNMENTS:   # `{feed:~#.000}`: an imported word
            return paid(nc_number(value, spec[1:]))                       # (engine.templates.nc_number)
        return paid(format(value, spec))
    return on_formattedvalue


def _call(interpreter):
    """The call handler: the named function (the gate allows no other) on its arguments.
    asteval's own puts every argument into the message of a failure, and a message must never
    render a large value."""
    def on_call(node):
        function = interpreter.run(node.func)
        return function(*[interpreter.run(argument) for argument in node.args])
    return on_call


def _problem(held: list, raised: Exception) -> str:
    """One line from the first failure asteval held: an unknown name as such, else the
    original exception (asteval's message around a call repeats its arguments)."""
    first = held[0] if held else None
    if first is not None and first.exc is NameError and isinstance(first.node, ast.Name):
        return f"unknown parameter {first.node.id!r}"
    original = first.exc_info[1] if first is not None and first.exc_info[1] is not None else raised
    text = " ".join(f"{type(original).__name__}: {original}".split())
    return text if len(text) <= MAX_MESSAGE else text[:MAX_MESSAGE - 1] + "…"


_THREAD = threading.local()   # an Interpreter holds the state of one evaluation: one per thread


def _own_evaluator() -> Evaluator:
    if not hasattr(_THREAD, "evaluator"):
        _THREAD.evaluator = Evaluator()
    return _THREAD.evaluator


def evaluate(compiled, scope: dict, budget: Budget | None = None):
    """One expression on its own (import, tests): `scope` holds its names; it spends `budget`,
    by default a whole instantiation's."""
    with spending(budget or Budget()):
        return _own_evaluator().evaluate(compiled.tree, compiled.text, {**scope, **base_symbols(compiled.is_sql)})


def evaluate_part(tree: ast.expr, text: str, is_sql: bool):
    """A part of an expression that reads no parameter, on its own budget (the gate's check),
    ending no later than the compile of its template (then that is the failure)."""
    outer = running()
    with spending(Budget.within(outer)):
        try:
            return _own_evaluator().evaluate(tree, text, base_symbols(is_sql))
        except EvaluationError:
            if outer is not None:
                outer.check_time()
            raise
