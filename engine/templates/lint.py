"""`engine lint`: every class's template as stored: its rows' structure and expressions
(engine.templates.checks), and that they name only parameters the class's model provides
or earlier rows compute."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..gears.models import model_for_class
from .checks import LintProblem, structural_problems
from .decision_table import compile_row, rows_compiled_once
from .expressions import translated_python
from .store import load_template
from .translations import store_translations

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .rows import Template


def lint_class(conn: Connection, gear_class: str, template: Template | None = None) -> list[LintProblem]:
    """Every problem of one class's template (its current rows, or the stored version given: a
    release re-checked), including unknown parameter names (its rows compiled once, within the
    time of one compile)."""
    with rows_compiled_once():
        return _class_problems(conn, gear_class, template or load_template(conn, gear_class))


def _class_problems(conn: Connection, gear_class: str, template: Template) -> list[LintProblem]:
    problems = structural_problems(gear_class, list(template.rows)) + _translation_problems(template)
    if problems:
        return problems
    name_source = _name_source(conn, gear_class)
    if name_source is None:
        return [LintProblem(gear_class, None, "model", "no hobbing model for this class or its ancestors, "
                            "so its parameter names cannot be checked; give the class a model, or import "
                            "it with `engine import-nc FILE --class NAME --params P.json`")]
    return list(_unknown_names(gear_class, template.rows, name_source))


def _name_source(conn: Connection, gear_class: str):
    """What tells the parameters a class's rows may read: an imported class's rows name the
    parameters of its program, even under a parent with a model; else the class's model."""
    return _imported_names(conn, gear_class) or model_for_class(conn, gear_class)


def known_names_of(conn: Connection, gear_class: str):
    """`(t, n) -> frozenset` of the parameter names a module's rows may read, or None when the
    class has no model nor import to say (engine lint reports that)."""
    source = _name_source(conn, gear_class)
    return None if source is None else source.parameter_names


def _translation_problems(template) -> list[LintProblem]:
    """A stored translation of a SQL condition must be what sqlglot makes of its text: one
    written by hand would give the condition another meaning than the text shows."""
    wrong = {text for text, python in template.translations.items() if translated_python(text) != python}
    return [LintProblem(template.gear_class, row.id, column, "its stored translation (table sql_translation) is "
                        "not sqlglot's; delete that row of sql_translation and run `engine lint` again")
            for row in template.rows for column in ("p_calc", "o", "p_emit") if getattr(row, column) in wrong]


class _ImportedNames(msgspec.Struct, frozen=True):
    """The names of an imported class: the parameters of the program it came from, in every module."""
    names: frozenset

    def parameter_names(self, t: str, n: int) -> frozenset:
        return self.names


def _imported_names(conn: Connection, gear_class: str) -> _ImportedNames | None:
    found = conn.execute("SELECT import_params FROM gear_class WHERE name = %s", (gear_class,)).fetchone()
    if found is None or found[0] is None:
        return None
    return _ImportedNames(frozenset(found[0]))


def _unknown_names(gear_class: str, rows, model):
    assigned: set[str] = set()
    for row in rows:
        compiled = compile_row(gear_class, row)
        known = model.parameter_names(row.t, row.n) | assigned
        for column, expression in _in_evaluation_order(compiled):
            for name in sorted(expression.names - known):
                yield LintProblem(gear_class, row.id, column, f"unknown parameter {name!r}")
            if column == "s":
                known = known | {n for n, c in compiled.s if c is expression}
        assigned |= {name for name, _ in compiled.s}


def _in_evaluation_order(compiled):
    if compiled.p_calc is not None:
        yield "p_calc", compiled.p_calc
    for _, statement in compiled.s:
        yield "s", statement
    for column in ("o", "p_emit"):
        expression = getattr(compiled, column)
        if expression is not None:
            yield column, expression


def lint_all(conn: Connection) -> list[LintProblem]:
    names = [row[0] for row in conn.execute(
        "SELECT DISTINCT gear_class FROM assembly ORDER BY gear_class")]
    problems = []
    for name in names:
        problems += lint_class(conn, name)
    if not problems:   # SQL conditions edited in SQL get their translation kept (engine.templates.translations)
        for name in names:
            store_translations(conn, load_template(conn, name).rows)
    return problems
