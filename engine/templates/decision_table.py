"""The expression-driven decision table (design notes §4, paper §3.2).

For each row in id order, with scope = job parameters ∪ parameters of module (T, N)
∪ intermediate variables computed so far:
1. if `s` is present: run it when `p_calc` is absent or true, else skip the whole row;
2. evaluate `o` to a string (absent `o`: the row only computes);
3. append it to the result when `p_emit` is absent or true.
Any failure aborts the whole instantiation with an error naming class, row, column, text.
"""
from __future__ import annotations

import ast
import time
from functools import partial
from dataclasses import dataclass, field

from ..errors import EngineError
from ..programs.nc_check import words
from ..turning.nc_path import NcLines
from .expressions import (MAX_SECONDS_PER_INSTANTIATION, Compiled, ExpressionError, compile_expression,
                          compile_statements, evaluation_globals)
from .guards import MAX_STRING_LENGTH
from .rows import Template, TemplateRow
from .template_code import build

MODULE_ORDER = ("main", "prep", "sync", "shift", "cutcond", "cutmotion")


class TemplateError(EngineError):
    """An expression of a template row failed: names class, row id, column and text."""

    def __init__(self, gear_class: str, row_id: int, column: str, text: str, problem: str):
        self.gear_class, self.row_id, self.column, self.text = gear_class, row_id, column, text
        super().__init__(f"class {gear_class} row {row_id} column {column}: {problem} in {text!r}")


@dataclass(frozen=True)
class CompiledRow:
    row: TemplateRow
    o: Compiled | None
    p_calc: Compiled | None
    s: tuple[tuple[str, Compiled], ...]
    p_emit: Compiled | None

    @property
    def module(self) -> tuple[str, int]:
        return self.row.t, self.row.n


@dataclass(slots=True)
class Result:
    """The result table of one instantiation: emitted lines and the row id of each."""
    lines: list[str] = field(default_factory=list)
    row_ids: list[int] = field(default_factory=list)


class CompiledTemplate:
    """A template parsed, checked and compiled once; `run` evaluates it for one job."""

    def __init__(self, template: Template):
        self.template = template
        self.rows = tuple(compile_row(template.gear_class, row) for row in template.rows)
        uses_sql = any(c.is_sql for r in self.rows for c in _expressions_of(r))
        self.globals = {**evaluation_globals(uses_sql), "_text": _text, "_clock": time.perf_counter}
        self.code, self.places = build(self.rows, template.gear_class)
        # Rows that print a whole tool path (nc_path) emit several lines at once.
        self.prints_paths = any(row.o is not None and _calls_nc_path(row.o.tree) for row in self.rows)
        # Lines a row always emits the same, parsed for the limit check once per template.
        self.constant_words = {row.row.id: words(row.o.tree.value) for row in self.rows
                               if row.o is not None and isinstance(row.o.tree, ast.Constant)
                               and isinstance(row.o.tree.value, str)}

    def run(self, params: dict, module_params: dict | None = None,
            deadline_seconds: float = MAX_SECONDS_PER_INSTANTIATION) -> Result:
        result = Result()
        scope = dict(params)
        scope["template_version"] = self.template.version
        scope["_mp"] = module_params = module_params or {}
        scope["_prev"] = False
        scope["_i"] = intermediates = {}
        scope["_enter"] = _module_switcher(scope, params, module_params, intermediates)
        scope["_deadline"] = time.perf_counter() + deadline_seconds
        scope["_timeout"] = partial(_timeout, deadline_seconds)
        scope["_lines_append"], scope["_rows_append"] = result.lines.append, result.row_ids.append
        try:
            exec(self.code, self.globals, scope)
        except TemplateError:
            raise
        except Exception as error:  # an expression's own failure, reported with its place
            raise self._error_at(error) from None
        return _one_line_each(result) if self.prints_paths else result

    def _error_at(self, error: Exception) -> TemplateError:
        place = self.places[_line_in_template(error.__traceback__, self.code.co_filename)]
        if isinstance(error, NameError):
            problem = f"unknown parameter {getattr(error, 'name', None) or error!r}"
        elif isinstance(error, _NotText):
            problem = str(error)
        else:
            problem = f"{type(error).__name__}: {error}"
        return TemplateError(self.template.gear_class, place.row_id, place.column, place.text, problem)


class _NotText(Exception):
    pass


def _calls_nc_path(tree) -> bool:
    return any(isinstance(node, ast.Call) and getattr(node.func, "id", None) == "nc_path" for node in ast.walk(tree))


def _one_line_each(result: Result) -> Result:
    """The blocks of an nc_path row as lines of their own, each with the row's id."""
    flat = Result()
    for line, row_id in zip(result.lines, result.row_ids):
        if isinstance(line, NcLines):
            flat.lines.extend(line)
            flat.row_ids.extend([row_id] * len(line))
        else:
            flat.lines.append(line)
            flat.row_ids.append(row_id)
    return flat


def _text(value):
    """`o` must give text (a bare number would print in whatever form Python chooses), of
    bounded length; or the blocks of nc_path."""
    if isinstance(value, NcLines):
        return value
    if type(value) is not str:
        raise _NotText(f"gives {type(value).__name__} {value!r}, not text "
                       "(write an f-string with a format, e.g. f\"X{x:.3f}\")")
    if len(value) > MAX_STRING_LENGTH:
        raise _NotText(f"gives a line longer than {MAX_STRING_LENGTH} characters")
    return value


def _line_in_template(traceback, filename: str) -> int:
    line = 0
    while traceback is not None:
        if traceback.tb_frame.f_code.co_filename == filename:
            line = traceback.tb_lineno
        traceback = traceback.tb_next
    return line


def _timeout(budget: float):
    raise TimeoutError(f"instantiation exceeded {budget} s")


def _module_switcher(scope: dict, params: dict, module_params: dict, intermediates: dict):
    """`_enter(key)`: module (T, N) parameters in, the previous module's out; intermediates stay."""
    previous: list = []

    def enter(key: str) -> None:
        for name in previous:
            if name not in intermediates:
                if name in params:
                    scope[name] = params[name]
                else:
                    scope.pop(name, None)
        current = module_params.get(key)
        previous[:] = current or ()
        scope["_prev"] = bool(current)
        if current:
            for name, value in current.items():
                if name not in intermediates:
                    scope[name] = value
    return enter


def compile_row(gear_class: str, row: TemplateRow) -> CompiledRow:
    def compiled(column: str, compile_function):
        text = getattr(row, column)
        if text is None:
            return None
        try:
            return compile_function(text)
        except ExpressionError as error:
            raise TemplateError(gear_class, row.id, column, text, str(error)) from None

    statements = compiled("s", compile_statements)
    return CompiledRow(row, compiled("o", compile_expression), compiled("p_calc", compile_expression),
                       tuple(statements or ()), compiled("p_emit", compile_expression))


def _expressions_of(row: CompiledRow):
    for compiled in (row.o, row.p_calc, row.p_emit):
        if compiled is not None:
            yield compiled
    for _, compiled in row.s:
        yield compiled


_CACHE: dict[tuple[str, int, str], CompiledTemplate] = {}


def compiled_template(template: Template) -> CompiledTemplate:
    """Parse every expression once per template (keyed by class, version and content)."""
    key = (template.gear_class, template.version, template.hash)
    found = _CACHE.get(key)
    if found is None:
        found = _CACHE[key] = CompiledTemplate(template)
    return found
