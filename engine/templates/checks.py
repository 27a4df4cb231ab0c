"""Checks of a template's rows before they are stored or run: structure (module type, ids,
rows that do nothing) and every expression parses and is allowed (design notes §4). Rows are
checked here, where every writer of rows comes through, not where they are loaded."""
from __future__ import annotations

import msgspec

from ..errors import EngineError
from .budget import compiling, pay_time
from .decision_table import TemplateError, compile_row
from .rows import MODULE_ORDER, TemplateRow, writes_lineage


class LintProblem(msgspec.Struct, frozen=True):
    """A fault of a template row found before it runs (engine lint, the release gate): the class, row and column."""
    gear_class: str
    row_id: int | None
    column: str
    message: str

    def __str__(self) -> str:
        where = f"row {self.row_id} column {self.column}" if self.row_id is not None else self.column
        return f"class {self.gear_class} {where}: {self.message}"


def check_rows(gear_class: str, rows: list[TemplateRow]) -> None:
    """Refuse rows that could never run: raise the first problem as an EngineError."""
    problems = structural_problems(gear_class, rows)
    if problems:
        raise EngineError(str(problems[0]) + (f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""))


def structural_problems(gear_class: str, rows: list[TemplateRow]) -> list[LintProblem]:
    """Every row's structure, and its expressions compiled within the time of one compile: the
    row at which that time ran out is a problem, and the rows after it are not compiled."""
    problems, out_of_time = [], False
    lineage: dict = {}   # o -> writes a lineage line: parsed once per text (a long program repeats lines)
    with compiling(len(rows)):
        for row in rows:
            problems += [LintProblem(gear_class, row.id, column, message)
                         for column, message in _row_structure(row, lineage)]
            if row.t in MODULE_ORDER and row.id >= 0 and not out_of_time:
                try:
                    compile_row(gear_class, row)
                except TemplateError as error:
                    problems.append(LintProblem(gear_class, row.id, error.column, str(error).split(": ", 1)[1]))
                    out_of_time = _out_of_time()
    return problems


def _out_of_time() -> bool:
    try:
        pay_time()
    except TimeoutError:
        return True
    return False


def _row_structure(row: TemplateRow, lineage: dict):
    if row.t not in MODULE_ORDER:
        yield "t", f"unknown module type {row.t!r}; use one of {', '.join(MODULE_ORDER)}"
    if row.id < 0 or row.n < 0:
        yield "id", "id and n must not be negative"
    if row.o is None and row.s is None:
        yield "o", "row has neither o nor s: it does nothing"
    if row.o not in lineage:
        lineage[row.o] = writes_lineage(row.o)
    if lineage[row.o]:
        yield "o", ("writes a line that reads as a lineage line, which only the engine writes (one per "
                    "program); remove the row")
    if row.p_calc is not None and row.s is None:
        yield "p_calc", "p_calc has no effect without s (use p_emit to decide output)"
