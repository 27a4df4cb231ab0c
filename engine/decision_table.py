"""The expression-driven decision table (design notes §4, paper §3.2).

For each row in id order, with scope = job parameters ∪ parameters of module (T, N)
∪ intermediate variables computed so far:
1. if `s` is present: run it when `p_calc` is absent or true, else skip the whole row;
2. evaluate `o` to a string (absent `o`: the row only computes);
3. append it to the result when `p_emit` is absent or true.
Any failure aborts the whole instantiation with an error naming class, row, column, text.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from .errors import EngineError
from .expressions import (MAX_SECONDS_PER_INSTANTIATION, Compiled, ExpressionError,
                          compile_expression, compile_statements, evaluation_globals)
from .templates import Template, TemplateRow

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


@dataclass
class Result:
    """The result table of one instantiation: emitted lines and the row id of each."""
    lines: list[str] = field(default_factory=list)
    row_ids: list[int] = field(default_factory=list)


def module_key(t: str, n: int) -> str:
    """How module parameters are keyed in a job: 'cutmotion:1'."""
    return f"{t}:{n}"


class CompiledTemplate:
    """A template parsed and compiled once; `run` evaluates it for one job."""

    def __init__(self, template: Template):
        self.template = template
        self.rows = tuple(_compile_row(template.gear_class, row) for row in template.rows)
        uses_sql = any(c.is_sql for r in self.rows for c in _expressions_of(r))
        self.globals = evaluation_globals(uses_sql)

    def run(self, params: dict, module_params: dict | None = None,
            deadline_seconds: float = MAX_SECONDS_PER_INSTANTIATION) -> Result:
        module_params = module_params or {}
        deadline = time.perf_counter() + deadline_seconds
        result, intermediates = Result(), {}
        scope, current_module = None, None
        for row in self.rows:
            if row.module != current_module:
                current_module = row.module
                scope = {**params, **module_params.get(module_key(*current_module), {}), **intermediates}
            if time.perf_counter() > deadline:
                raise self._error(row, "o", f"instantiation exceeded {deadline_seconds} s")
            self._run_row(row, scope, intermediates, result)
        return result

    def _run_row(self, row: CompiledRow, scope: dict, intermediates: dict, result: Result) -> None:
        if row.s:
            if row.p_calc is not None and not self._evaluate(row, "p_calc", row.p_calc, scope):
                return  # paper step 4: compute condition false skips the whole row
            for name, statement in row.s:
                value = self._evaluate(row, "s", statement, scope)
                scope[name] = intermediates[name] = value
        if row.o is None:
            return
        text = self._evaluate(row, "o", row.o, scope)
        if not isinstance(text, str):
            raise self._error(row, "o", f"gives {type(text).__name__} {text!r}, not text "
                                        "(write an f-string with a format, e.g. f\"X{x:.3f}\")")
        if row.p_emit is None or self._evaluate(row, "p_emit", row.p_emit, scope):
            result.lines.append(text)
            result.row_ids.append(row.row.id)

    def _evaluate(self, row: CompiledRow, column: str, compiled: Compiled, scope: dict):
        try:
            return eval(compiled.code, self.globals, scope)
        except NameError as error:
            name = getattr(error, "name", None) or str(error)
            raise self._error(row, column, f"unknown parameter {name!r}", compiled.text) from None
        except Exception as error:  # an expression's own failure, reported with its place
            problem = f"{type(error).__name__}: {error}"
            raise self._error(row, column, problem, compiled.text) from None

    def _error(self, row: CompiledRow, column: str, problem: str, text: str | None = None):
        text = text if text is not None else (getattr(row.row, column) or "")
        return TemplateError(self.template.gear_class, row.row.id, column, text, problem)


def _compile_row(gear_class: str, row: TemplateRow) -> CompiledRow:
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
