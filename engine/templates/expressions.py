"""Template expressions: parsed once, checked against a whitelist, guarded, then run by asteval
(engine.templates.evaluator).

An expression is a Python expression (f-strings are the natural way to write NC lines) or,
when the text is not Python, a condition written the way a DBA writes SQL; sqlglot
translates it once (engine.templates.sqlcond) into Python that calls the `_sql_*` helpers.
`s` holds assignments `name = expr`, separated by `;` or new lines.

Two layers. Ours, the gate, runs at import, at lint and whenever a template is compiled:
no statements other than plain assignments in `s` (never to an engine name), no loops,
comprehensions, lambdas, attribute access, bytes, imports or calls other than the named
functions (engine.templates.functions); at most MAX_NODES nodes nested at most MAX_DEPTH
deep. The operators that can allocate without bound (`**`, `*`, `+`, `<<`, `%`), f-strings,
list and tuple displays and dynamic format specs are rewritten into calls of the guards of
engine.templates.guards, which bound every value an expression builds. Behind the gate,
asteval's interpreter runs the guarded tree with only our functions in its symbol table.
Every expression therefore runs in time bounded by its size; an instantiation spends one budget of
time and bytes as well (engine.templates.budget).
"""
from __future__ import annotations

import ast
import re
from collections.abc import Mapping
from typing import Literal, overload

import msgspec

from ..errors import EngineError
from .functions import CONSTANTS, FUNCTIONS
from .guards import MAX_INT_BITS, check_format_spec, parse_python
from .plain_lines import plain
from .tree_walk import ExpressionTree

MAX_EXPRESSION_LENGTH = 4_000      # characters of one expression or statement block
MAX_NODES = 400                    # AST nodes of one expression
MAX_DEPTH = 40                     # nesting of one expression (asteval walks the tree recursively)
MAX_TRANSLATION_LENGTH = 4 * MAX_EXPRESSION_LENGTH   # the Python a SQL condition is translated into
ENGINE_NAMES = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"template_version"}

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


class Compiled(msgspec.Struct, frozen=True):
    """One checked expression: its text, the guarded tree asteval runs, the names it reads."""
    text: str
    tree: ast.expr
    names: frozenset[str]      # parameter/variable names it reads
    is_sql: bool = False
    ordered_names: tuple[str, ...] = ()   # the names, sorted (the trace lists them in this order)
    calls: frozenset[str] = frozenset()   # the functions it calls


class ExpressionError(EngineError):
    """An expression that does not parse, is not allowed, or fails when evaluated."""


def compile_expression(text: str, translations: Mapping[str, str] | None = None) -> Compiled:
    """Parse `text` as Python, else as SQL (its stored translation if `translations` has one);
    check it; guard it."""
    _check_length(text)
    try:
        tree = _parsed(text.strip(), "eval")
        is_sql = False
    except SyntaxError as python_error:
        tree, is_sql = _sql_tree(text, python_error, translations or {}), True
    found = None if is_sql else plain(tree.body, MAX_NODES)
    if found is not None:
        body, names, calls = found
        return Compiled(text, body, names, False, tuple(sorted(names)), calls)
    return _fully_checked(text, tree, is_sql)


def _fully_checked(text: str, tree: ast.Expression, is_sql: bool) -> Compiled:
    """The whole gate on a parsed expression: checked, its constant parts evaluated, guarded."""
    walk = ExpressionTree(tree, MAX_DEPTH, ExpressionError(f"nested too deeply (at most {MAX_DEPTH} levels)"))
    _check_tree(walk, sql_helpers=is_sql)
    names = frozenset(_read_names(walk))
    parts = walk.parts_without(_is_parameter)
    replaced = _guarded(walk)
    if parts:
        _check_constant_parts([replaced.get(id(part), part) for part in parts], parts, text.strip(), is_sql)
    body = ast.Call(ast.Name("_sql_truth", ast.Load()), [tree.body], []) if is_sql else tree.body
    calls = frozenset(node.func.id for node in walk.of_type(ast.Call))
    return Compiled(text, body, names, is_sql, tuple(sorted(names)), calls)


def _check_constant_parts(guarded: list, parts: list, source: str, is_sql: bool) -> None:
    """Every part that reads no parameter (`[[0] * 65536] * 65536`, `10 ** 10 ** 6`) is evaluated
    here, under the bounds of one instantiation: one that fails would fail for every job, so the
    template is refused where it enters (import, lint, compile), not at its first job."""
    from .evaluator import EvaluationError, evaluate_part  # asteval: only where a template is compiled

    for part, original in zip(guarded, parts):
        try:
            evaluate_part(part, source, is_sql)
        except EvaluationError as error:
            text = None if is_sql else ast.get_source_segment(source, original)
            what = "it" if text is None or text == source else text
            raise ExpressionError(f"{what} fails for every job: {error}") from None


def _is_parameter(name: str) -> bool:
    return name not in FUNCTIONS and name not in CONSTANTS and not name.startswith("_")


@overload
def _parsed(text: str, mode: Literal["eval"]) -> ast.Expression: ...
@overload
def _parsed(text: str, mode: Literal["exec"]) -> ast.Module: ...
def _parsed(text: str, mode: str) -> ast.AST:
    """ast.parse, with a nesting too deep for the parser refused like any other bad text."""
    try:
        return parse_python(text, mode)
    except (RecursionError, MemoryError):
        raise ExpressionError(f"nested too deeply (at most {MAX_DEPTH} levels)") from None


def compile_statements(text: str) -> list[tuple[str, Compiled]]:
    """`s`: assignments `name = expr` separated by `;` or new lines, in order."""
    _check_length(text)
    try:
        module = _parsed(text.strip(), "exec")
    except SyntaxError as error:
        raise ExpressionError(f"does not parse: {error.msg} (column {error.offset})") from None
    assignments, lines = [], _LINES.findall(text.strip())
    for statement in module.body:
        if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1
                and isinstance(statement.targets[0], ast.Name)):
            kind = type(statement).__name__
            raise ExpressionError(f"only assignments `name = expression` are allowed, not {kind}")
        name = statement.targets[0].id
        _check_name(name)
        if name in ENGINE_NAMES:
            raise ExpressionError(f"{name!r} is a name of the engine (a function, constant or the "
                                  "template version); assign to another name")
        assignments.append((name, compile_expression(_source_of(lines, statement.value))))
    if not assignments:
        raise ExpressionError("no assignment found")
    return assignments


_LINES = re.compile(r"[^\r\n]*(?:\r\n|\r|\n|$)")   # the lines as Python's parser counts them (not str.splitlines)


def _source_of(lines: list[str], node: ast.expr) -> str:
    """The text of `node` (ast.get_source_segment splits the whole text again for each node:
    quadratic in a block of a few hundred statements). Offsets count UTF-8 bytes."""
    assert node.end_lineno is not None and node.end_col_offset is not None   # a parsed node has its end
    first, last = node.lineno - 1, node.end_lineno - 1
    if first == last:
        return lines[first].encode()[node.col_offset:node.end_col_offset].decode()
    head = lines[first].encode()[node.col_offset:].decode()
    return head + "".join(lines[first + 1:last]) + lines[last].encode()[:node.end_col_offset].decode()


def _check_length(text: str) -> None:
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise ExpressionError(f"longer than {MAX_EXPRESSION_LENGTH} characters")
    if not text.strip():
        raise ExpressionError("empty expression")


def translated_python(text: str) -> str | None:
    """The Python expression sqlglot makes of a SQL condition (None if it is not one), to keep."""
    try:
        python_error = _python_error(text)
        return None if python_error is None else ast.unparse(_parse_sql(text, python_error).body)
    except ExpressionError:
        return None


def _python_error(text: str) -> SyntaxError | None:
    try:
        _parsed(text.strip(), "eval")
    except SyntaxError as error:
        return error
    return None


def _sql_tree(text: str, python_error: SyntaxError, translations: Mapping[str, str]) -> ast.Expression:
    """A stored translation (checked by the gate like any tree), else sqlglot's."""
    stored = translations.get(text)
    if stored is None:
        return _parse_sql(text, python_error)
    if len(stored) > MAX_TRANSLATION_LENGTH:
        raise ExpressionError(f"its stored translation (table sql_translation) is longer than "
                              f"{MAX_TRANSLATION_LENGTH} characters; delete that row and run `engine lint`")
    try:
        return _parsed(stored, "eval")
    except SyntaxError:
        raise ExpressionError("its stored translation (table sql_translation) does not parse; "
                              "delete that row and run `engine lint`") from None


def _parse_sql(text: str, python_error: SyntaxError) -> ast.Expression:
    from .sqlcond.translate import translate  # sqlglot: only where a condition is translated

    try:
        return ast.Expression(body=translate(text))
    except RecursionError:
        raise ExpressionError(f"nested too deeply (at most {MAX_DEPTH} levels)") from None
    except EngineError as sql_error:
        raise ExpressionError(
            f"not a Python expression ({python_error.msg}, column {python_error.offset}) "
            f"nor SQL ({sql_error})"
        ) from None


def _check_tree(walk: ExpressionTree, sql_helpers: bool = False) -> None:
    """The gate: only allowed nodes, named functions and names; bounded in size and depth (the
    walk refused a deeper tree). `_sql_*` helpers only in the translation of a SQL condition,
    never in Python text."""
    for node in walk.nodes:
        if not isinstance(node, ALLOWED_NODES):
            raise ExpressionError(f"{_describe(node)} is not allowed in a template expression")
        if isinstance(node, ast.Constant):
            _check_constant(node.value)
        if isinstance(node, ast.FormattedValue) and isinstance(node.format_spec, ast.JoinedStr):   # or None
            _check_spec_fields(node.format_spec)
        if isinstance(node, ast.Call):
            _check_call(node, sql_helpers)
        if _formats_with_percent(node):
            raise ExpressionError("'%' string formatting is not allowed; use an f-string")
        if isinstance(node, ast.Name):
            _check_name(node.id, sql_helpers)
    if len(walk.nodes) > MAX_NODES:
        raise ExpressionError(f"expression too large ({len(walk.nodes)} nodes, at most {MAX_NODES})")
    misused = _function_names_as_values(walk)
    if misused:
        raise ExpressionError(f"{misused[0]} is a function: call it, {misused[0]}(…)")


def _check_constant(value) -> None:
    if isinstance(value, bytes):
        raise ExpressionError("bytes literals are not allowed (NC lines are text)")
    if isinstance(value, int) and value.bit_length() > MAX_INT_BITS:
        raise ExpressionError(f"integer literal larger than {MAX_INT_BITS} bits")


def _formats_with_percent(node: ast.AST) -> bool:
    """`'…' % x` on a written text: refused here as the guard refuses it at run time (its width
    is not bounded), so that lint names it without a job."""
    return isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod) and (
        isinstance(node.left, ast.JoinedStr)
        or isinstance(node.left, ast.Constant) and isinstance(node.left.value, str))


def _check_spec_fields(spec: ast.JoinedStr) -> None:
    """A format spec may take a field from a name or a constant (`{x:>{width}}`), nothing more:
    no operators, calls or nested specs run inside it."""
    for part in spec.values:
        if isinstance(part, ast.FormattedValue) and (
                not isinstance(part.value, (ast.Name, ast.Constant)) or part.conversion != -1
                or part.format_spec is not None):
            raise ExpressionError("a format spec may take only a name or a constant in its {field}")


def _function_names_as_values(walk: ExpressionTree):
    """Names of functions used other than as the called name: an NC line would print
    `<function …>`."""
    called = {id(node.func) for node in walk.of_type(ast.Call)}
    return [node.id for node in walk.of_type(ast.Name) if node.id in FUNCTIONS and id(node) not in called]


def _check_call(node: ast.Call, sql_helpers: bool) -> None:
    if not isinstance(node.func, ast.Name):
        raise ExpressionError("only calls of named functions are allowed")
    name = node.func.id
    if name not in FUNCTIONS and not (sql_helpers and name.startswith("_sql_")):
        known = ", ".join(sorted(FUNCTIONS))
        raise ExpressionError(f"function {name}() is not available; known: {known}")
    if node.keywords:
        raise ExpressionError(f"keyword arguments are not allowed in {name}()")


def _check_name(name: str, sql_helpers: bool = False) -> None:
    if name.startswith("_") and not (sql_helpers and name.startswith("_sql_")):
        raise ExpressionError(f"name {name!r} is not allowed (names starting with _ are reserved)")


def _describe(node: ast.AST) -> str:
    descriptions = {ast.Attribute: "attribute access (.name)", ast.Lambda: "lambda",
                    ast.NamedExpr: "assignment (:=)", ast.ListComp: "a comprehension",
                    ast.GeneratorExp: "a generator", ast.Dict: "a dict", ast.Starred: "*args"}
    return descriptions.get(type(node), type(node).__name__)


def _read_names(walk: ExpressionTree):
    for node in walk.of_type(ast.Name):
        if node.id not in FUNCTIONS and node.id not in CONSTANTS and not node.id.startswith("_sql_"):
            yield node.id


def _constant_spec(spec: ast.JoinedStr) -> str | None:
    """The text of a format spec without replacement fields, else None."""
    texts = [part.value for part in spec.values if isinstance(part, ast.Constant) and isinstance(part.value, str)]
    return "".join(texts) if len(texts) == len(spec.values) else None


def _guarded(walk: ExpressionTree) -> dict[int, ast.AST]:
    """Route the operators that can allocate without bound through the guards, in place, children
    before their parents. Returns the node that took the place of each node replaced (a part's
    guarded form). A format spec is checked, never wrapped."""
    replaced = {}
    for node in reversed(walk.nodes):
        instead = _guard_of(node, walk)
        if instead is not node:
            walk.put(node, instead)
            replaced[id(node)] = instead
    return replaced


def _guard_of(node: ast.AST, walk: ExpressionTree) -> ast.AST:
    if type(node) is ast.BinOp:
        guard = GUARDED_OPERATORS.get(type(node.op))
        return node if guard is None else _call(guard, [node.left, node.right], node)
    if type(node) is ast.JoinedStr:
        return node if walk.slots[id(node)][1] == "format_spec" else _call("_guard", [node], node)
    if type(node) is ast.List or type(node) is ast.Tuple:   # a display of constants is bounded by the text
        constants = all(isinstance(element, ast.Constant) for element in node.elts)
        return node if constants else _call("_guard", [node], node)
    if type(node) is ast.Subscript:                 # a slice copies what it cuts: paid like any built value
        return _call("_built", [node], node) if isinstance(node.slice, ast.Slice) else node
    if type(node) is ast.FormattedValue:
        return _field(node)
    return node


def _call(guard: str, arguments: list, node: ast.AST) -> ast.Call:
    return ast.copy_location(ast.Call(ast.Name(guard, ast.Load()), arguments, []), node)


def _field(node: ast.FormattedValue) -> ast.FormattedValue:
    """A fixed format spec is checked once, here; a computed one by _safe_format when it runs."""
    if node.conversion != -1:
        raise ExpressionError("conversions (!r, !s, !a) are not allowed in f-strings")
    spec = node.format_spec
    assert spec is None or isinstance(spec, ast.JoinedStr)   # Python parses a format spec as an f-string
    constant = None if spec is None else _constant_spec(spec)
    if spec is None or constant is not None:
        if constant is not None:
            try:
                check_format_spec(constant)
            except ValueError as error:
                raise ExpressionError(str(error)) from None
        return node
    return ast.copy_location(ast.FormattedValue(_call("_safe_format", [node.value, spec], node), -1, None), node)
