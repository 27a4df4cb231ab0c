"""Static analysis of a class's assembled template, the third check of the release gate (issue 15):
rows that parse and name known parameters (engine lint) can still be wrong in ways no single
expression shows. Each rule below looks at the rows together, in evaluation order:

* a condition (`p_calc`, `p_emit`) that reads no name and is false: the row never computes or
  never prints, for every job — an edit that switched a line off by accident;
* two rows writing the same intermediate with nothing between them reading it, the second
  unconditionally: the first write is dead (a copied row whose name was not changed);
* a row identical to an earlier one (t, n, p_calc, s, o, p_emit) where the repeat cannot be the
  program's content (REPEAT_MISTAKES): right after its twin (a row pasted twice), or a row that
  computes (its second identical condition or assignment is dead). Real programs repeat plain
  lines far apart (a retract, a tool call: 1 to 26 rows per LinuxCNC file of tests/data/nc) and
  blank lines side by side, so those repeats are content and an imported program can be released;
* a name read before any row or parameter gives it: a row reads a name that its module's
  parameters do not hold and only a later row (or none) assigns.

Every expression is compiled and evaluated through the expression gate
(engine.templates.expressions, engine.templates.evaluator), never Python's eval."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from .decision_table import CompiledRow, compile_row
from .evaluator import EvaluationError, evaluate
from .lint import known_names_of
from .rows import Template

if TYPE_CHECKING:
    from ..db.connection import Connection

CONDITION_COLUMNS = ("p_calc", "p_emit")


class Finding(msgspec.Struct, frozen=True):
    """One problem the analysis found: where (row, column) and what, in one line."""
    gear_class: str
    row_id: int
    column: str
    rule: str
    message: str

    def __str__(self) -> str:
        return f"class {self.gear_class} row {self.row_id} column {self.column}: {self.message} ({self.rule})"


def analyse(template: Template, known_names=None) -> list[Finding]:
    """Every finding of every rule (RULES) on the template's rows, in row order. `known_names(t, n)`
    gives the parameters a module's rows may read (a model's parameter_names); without it the
    read-before-given rule is not run (lint reports a class without a model)."""
    compiled = [compile_row(template.gear_class, row, template.translations) for row in template.rows]
    findings = []
    for rule, check in RULES:
        if rule != "read-before-given" or known_names is not None:
            findings += [Finding(template.gear_class, row_id, column, rule, message)
                         for row_id, column, message in check(compiled, known_names)]
    return sorted(findings, key=lambda finding: (finding.row_id, finding.column, finding.rule))


def constant_false(rows: list[CompiledRow], known_names):
    """A condition that reads no name and evaluates false: the row is off for every job."""
    for row in rows:
        for column in CONDITION_COLUMNS:
            condition = getattr(row, column)
            if condition is not None and not condition.names and _is_false(condition):
                yield row.row.id, column, f"{condition.text!r} is false for every job: the row never " + (
                    "computes" if column == "p_calc" else "prints")


def _is_false(condition) -> bool:
    try:
        return not evaluate(condition, {})
    except EvaluationError:
        return False   # a condition failing for every job is lint's to report


def dead_writes(rows: list[CompiledRow], known_names):
    """An intermediate assigned again, unconditionally, before any row reads it."""
    pending: dict[str, list[int]] = {}   # name -> rows whose write no row has read yet
    for row in rows:
        for name in _names_read(row):
            pending.pop(name, None)
        for name in dict.fromkeys(name for name, _ in row.s):
            if row.p_calc is None:
                for earlier in pending.pop(name, ()):
                    yield earlier, "s", (f"assigns {name!r}, which row {row.row.id} assigns again "
                                         "unconditionally before any row reads it")
            pending.setdefault(name, []).append(row.row.id)


def _names_read(row: CompiledRow) -> set[str]:
    expressions = [row.p_calc, row.o, row.p_emit, *(value for _, value in row.s)]
    return {name for expression in expressions if expression is not None for name in expression.names}


def duplicates(rows: list[CompiledRow], known_names):
    """A row identical (t, n, p_calc, s, o, p_emit) to an earlier row, where a rule of
    REPEAT_MISTAKES says the repeat is a mistake and not the program's content."""
    first: dict[tuple, int] = {}
    previous = None
    for row in rows:
        body = _body(row)
        adjacent = previous is not None and _body(previous) == body
        why = _mistake(row, adjacent) if body in first else None
        if why is not None:
            twin = previous.row.id if adjacent and previous is not None else first[body]
            yield row.row.id, "o", f"repeats row {twin} exactly (t, n, p_calc, s, o, p_emit) {why}"
        first.setdefault(body, row.row.id)
        previous = row


def _body(row: CompiledRow) -> tuple:
    return row.row.values()[1:]


def _mistake(row: CompiledRow, adjacent: bool) -> str | None:
    """Why the repeat is a mistake (the first rule of REPEAT_MISTAKES that holds), or None: content."""
    return next((why for is_mistake, why in REPEAT_MISTAKES if is_mistake(row, adjacent)), None)


def _computes(row: CompiledRow, adjacent: bool) -> bool:
    """A condition or assignment: done again with the same inputs, it decides or gives nothing new."""
    return any(getattr(row.row, column) for column in ("p_calc", "s", "p_emit"))


def _pasted(row: CompiledRow, adjacent: bool) -> bool:
    """The same line right after itself: a block said twice in a row is a paste (no program of
    tests/data/nc has one), but blank lines do come in pairs (4 of its 12 LinuxCNC files)."""
    return adjacent and not _prints_blank(row)


def _prints_blank(row: CompiledRow) -> bool:
    if row.o is None or row.o.names or row.o.calls:
        return False
    try:
        line = evaluate(row.o, {})
    except EvaluationError:
        return False   # a line failing for every job is lint's to report
    return isinstance(line, str) and not line.strip()


# When a repeated row is a mistake, not the program's content: (is it(row, right after its twin), why).
# A plain line repeated further on is content: a retract or tool call comes back in real programs.
REPEAT_MISTAKES = (
    (_computes, "and computes: the second identical condition or assignment is dead"),
    (_pasted, "right after it: a row pasted twice"),
)


def read_before_given(rows: list[CompiledRow], known_names):
    """A name a row reads that its module's parameters do not hold and no earlier row assigns."""
    assigned_at: dict[str, int] = {}   # name -> the row that first assigns it
    for row in rows:
        for name, _ in row.s:
            assigned_at.setdefault(name, row.row.id)
    given: set[str] = set()
    for row in rows:
        known = known_names(row.row.t, row.row.n) | given
        for column, name in _reads_in_order(row):
            if name not in known:
                yield row.row.id, column, _not_given(name, assigned_at.get(name))
                known = known | {name}
        given |= {name for name, _ in row.s}


def _reads_in_order(row: CompiledRow):
    """(column, name) the row reads before assigning the name itself, in evaluation order."""
    assigned: set[str] = set()
    steps = [("p_calc", row.p_calc, None), *(("s", value, name) for name, value in row.s),
             ("o", row.o, None), ("p_emit", row.p_emit, None)]
    for column, expression, target in steps:
        if expression is not None:
            yield from ((column, name) for name in sorted(expression.names - assigned))
        if target is not None:
            assigned.add(target)


def _not_given(name: str, later_row: int | None) -> str:
    if later_row is not None:
        return f"reads {name!r} before row {later_row} assigns it"
    return f"reads {name!r}, which no parameter of the class and no row gives"


# The rules, in the order their findings are explained: (name, check(compiled rows, known_names)).
RULES = (
    ("constant-false", constant_false),
    ("dead-write", dead_writes),
    ("duplicate-row", duplicates),
    ("read-before-given", read_before_given),
)


def class_findings(conn: Connection, gear_class: str, template: Template) -> list[Finding]:
    """The analysis of a stored class's template, with the names its model (or import) provides."""
    return analyse(template, known_names_of(conn, gear_class))
