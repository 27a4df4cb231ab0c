"""Template expressions: parsed once, checked against a whitelist, compiled, evaluated safely.

An expression is a Python expression (f-strings are the natural way to write NC lines) or,
when the text is not Python, a condition written the way a DBA writes SQL; sqlglot
translates it (engine.templates.sqlcond). `s` holds assignments `name = expr`, separated by `;` or
new lines.

Safety comes from the shape of what is allowed, not from watching a running program:
no statements other than plain assignments in `s`, no loops, comprehensions, lambdas,
attribute access, imports or calls other than the named functions (engine.templates.functions);
the operators that can blow up (`**`, `*`, `+`, `<<`, `%`) and format widths go through the
guards of engine.templates.guards (asteval's own guards and limits, applied to compiled code). Every
expression therefore runs in time bounded by its size. A wall-clock budget per
instantiation is kept as a second line of defence (engine.templates.decision_table).

We compile to Python code objects instead of walking the tree with asteval at every
evaluation: the batch target (5,000 programs/s) leaves about 2 µs per expression, and a
tree walk costs ten times that. `evaluate_with_asteval` runs the same text through an
asteval Interpreter; tests check both agree on every seeded template.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from typing import Any

from ..errors import EngineError
from .functions import CONSTANTS, FUNCTIONS
from .guards import (check_format_spec, guard_length, safe_add, safe_format, safe_lshift, safe_mod,
                     safe_mult, safe_pow)

MAX_EXPRESSION_LENGTH = 4_000      # characters of one expression or statement block
MAX_NODES = 400                    # AST nodes of one expression
MAX_SECONDS_PER_INSTANTIATION = 2.0

ALLOWED_NODES = (
    ast.Expression, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp, ast.Call,
    ast.Name, ast.Load, ast.Constant, ast.JoinedStr, ast.FormattedValue, ast.Tuple, ast.List,
    ast.Subscript, ast.Slice,
    ast.Add, ast.Sub, ast.Mult, ast.Div, ast.FloorDiv, ast.Mod, ast.Pow, ast.LShift, ast.RShift,
    ast.BitAnd, ast.BitOr, ast.BitXor, ast.USub, ast.UAdd, ast.Not, ast.Invert, ast.And, ast.Or,
    ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.In, ast.NotIn, ast.Is, ast.IsNot,
)


GUARDED_OPERATORS = {ast.Pow: "_safe_pow", ast.Mult: "_safe_mult", ast.Add: "_safe_add",
                     ast.LShift: "_safe_lshift", ast.Mod: "_safe_mod"}
RUNTIME = {"_safe_pow": safe_pow, "_safe_mult": safe_mult, "_safe_add": safe_add,
           "_safe_lshift": safe_lshift, "_safe_mod": safe_mod, "_safe_format": safe_format,
           "_guard": guard_length}


def _sql_runtime() -> dict:
    from .sqlcond import SQL_RUNTIME   # sqlglot: loaded only by templates with SQL conditions

    return SQL_RUNTIME


def evaluation_globals(uses_sql: bool = False) -> dict:
    """The globals every compiled expression runs with: no builtins, only our functions."""
    names = {"__builtins__": {}, **FUNCTIONS, **CONSTANTS, **RUNTIME}
    if uses_sql:
        names.update(_sql_runtime())
    return names


@dataclass(frozen=True)
class Compiled:
    """One checked and compiled expression."""
    text: str
    code: Any                  # code object, eval()-able
    names: frozenset[str]      # parameter/variable names it reads
    is_sql: bool = False
    tree: Any = None           # the checked and guarded expression node (for whole-template code)


class ExpressionError(EngineError):
    """An expression that does not parse, is not allowed, or fails when evaluated."""


def compile_expression(text: str) -> Compiled:
    """Parse `text` as Python, else as SQL; check it; compile it."""
    _check_length(text)
    try:
        tree = ast.parse(text.strip(), mode="eval")
        is_sql = False
    except SyntaxError as python_error:
        tree, is_sql = _parse_sql(text, python_error), True
    _check_tree(tree)
    names = frozenset(_read_names(tree))
    tree = _GuardOperators().visit(tree)
    if is_sql:
        tree = ast.Expression(body=ast.Call(ast.Name("_sql_truth", ast.Load()), [tree.body], []))
    ast.fix_missing_locations(tree)
    return Compiled(text, compile(tree, "<template>", "eval"), names, is_sql, tree.body)


def compile_statements(text: str) -> list[tuple[str, Compiled]]:
    """`s`: assignments `name = expr` separated by `;` or new lines, in order."""
    _check_length(text)
    try:
        module = ast.parse(text.strip(), mode="exec")
    except SyntaxError as error:
        raise ExpressionError(f"does not parse: {error.msg} (column {error.offset})") from None
    assignments = []
    for statement in module.body:
        if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1
                and isinstance(statement.targets[0], ast.Name)):
            kind = type(statement).__name__
            raise ExpressionError(f"only assignments `name = expression` are allowed, not {kind}")
        name = statement.targets[0].id
        _check_name(name)
        source = ast.get_source_segment(text.strip(), statement.value)
        assignments.append((name, compile_expression(source)))
    if not assignments:
        raise ExpressionError("no assignment found")
    return assignments


def _check_length(text: str) -> None:
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise ExpressionError(f"longer than {MAX_EXPRESSION_LENGTH} characters")
    if not text.strip():
        raise ExpressionError("empty expression")


def _parse_sql(text: str, python_error: SyntaxError) -> ast.Expression:
    from .sqlcond import translate   # sqlglot, as above

    try:
        return ast.Expression(body=translate(text))
    except EngineError as sql_error:
        raise ExpressionError(
            f"not a Python expression ({python_error.msg}, column {python_error.offset}) "
            f"nor SQL ({sql_error})"
        ) from None


def _check_tree(tree: ast.AST) -> None:
    count = 0
    for node in ast.walk(tree):
        count += 1
        if not isinstance(node, ALLOWED_NODES):
            raise ExpressionError(f"{_describe(node)} is not allowed in a template expression")
        if isinstance(node, ast.Call):
            _check_call(node)
        if isinstance(node, ast.Name):
            _check_name(node.id)
    if count > MAX_NODES:
        raise ExpressionError(f"expression too large ({count} nodes, at most {MAX_NODES})")


def _check_call(node: ast.Call) -> None:
    if not isinstance(node.func, ast.Name):
        raise ExpressionError("only calls of named functions are allowed")
    name = node.func.id
    if name not in FUNCTIONS and not name.startswith("_sql_"):
        known = ", ".join(sorted(FUNCTIONS))
        raise ExpressionError(f"function {name}() is not available; known: {known}")
    if node.keywords:
        raise ExpressionError(f"keyword arguments are not allowed in {name}()")


def _check_name(name: str) -> None:
    if name.startswith("_") and not name.startswith("_sql_"):
        raise ExpressionError(f"name {name!r} is not allowed (names starting with _ are reserved)")


def _describe(node: ast.AST) -> str:
    descriptions = {ast.Attribute: "attribute access (.name)", ast.Lambda: "lambda",
                    ast.NamedExpr: "assignment (:=)", ast.ListComp: "a comprehension",
                    ast.GeneratorExp: "a generator", ast.Dict: "a dict", ast.Starred: "*args"}
    return descriptions.get(type(node), type(node).__name__)


def _read_names(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in FUNCTIONS and node.id not in CONSTANTS \
                and not node.id.startswith("_sql_"):
            yield node.id


def _constant_spec(spec: ast.JoinedStr) -> str | None:
    """The text of a format spec without replacement fields, else None."""
    if all(isinstance(part, ast.Constant) for part in spec.values):
        return "".join(part.value for part in spec.values)
    return None


class _GuardOperators(ast.NodeTransformer):
    """Route the operators that can allocate without bound through the guards."""

    def visit_BinOp(self, node: ast.BinOp):
        self.generic_visit(node)
        guard = GUARDED_OPERATORS.get(type(node.op))
        if guard is None:
            return node
        return ast.copy_location(
            ast.Call(ast.Name(guard, ast.Load()), [node.left, node.right], []), node)

    def visit_JoinedStr(self, node: ast.JoinedStr):
        self.generic_visit(node)
        return ast.copy_location(ast.Call(ast.Name("_guard", ast.Load()), [node], []), node)

    def visit_FormattedValue(self, node: ast.FormattedValue):
        if node.conversion != -1:
            raise ExpressionError("conversions (!r, !s, !a) are not allowed in f-strings")
        spec = node.format_spec
        if spec is None or _constant_spec(spec) is not None:
            if spec is not None:
                try:
                    check_format_spec(_constant_spec(spec))  # fixed spec: checked once, here
                except ValueError as error:
                    raise ExpressionError(str(error)) from None
            node.value = self.visit(node.value)
            return node
        value = ast.Call(ast.Name("_safe_format", ast.Load()), [self.visit(node.value), spec], [])
        return ast.copy_location(ast.FormattedValue(value, -1, None), node)


ASTEVAL_CONFIG = {"ifexp": True, "formattedvalue": True}


def evaluate_with_asteval(text: str, scope: dict) -> Any:
    """Reference evaluation of one expression by asteval's interpreter (tests, diagnostics)."""
    import asteval

    interpreter = asteval.Interpreter(minimal=True, use_numpy=False, config=ASTEVAL_CONFIG, user_symbols={
        **FUNCTIONS, **{k: v for k, v in CONSTANTS.items() if k[0].islower()}, **scope})
    try:
        ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        compiled = compile_expression(text)
        return eval(compiled.code, evaluation_globals(True), dict(scope))
    result = interpreter.eval(text.strip(), show_errors=False, raise_errors=True)
    return result
