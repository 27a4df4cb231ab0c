"""Golden tests of templates (`engine test`, issue 15): each row of template_test names a
workpiece (a seeded gear, or a job's parameters), the job's choices and what its program must
show. The release gate runs them against a class's draft before it is released; an editor runs
them after a change. Nothing is stored: the program is made in memory as `engine instantiate`
would make it (engine.release.golden_runs), with the verifier and the simulation, so a
program they refuse fails its test with their reason, and so does a broken expression (the
message names class, row and column).

The expectation language is engine.templates.expectations's (docs/guide/release-and-golden-tests.md)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..templates.expectations import Context, first_difference
from ..templates.versions import runnable_template
from .golden_runs import GoldenTest, made_program

if TYPE_CHECKING:
    from ..db.connection import Connection

TESTS = ("SELECT id, gear_class, name, gear_id, params, choices, expect, description FROM template_test "
         "WHERE %(all)s OR gear_class = ANY(%(classes)s) ORDER BY gear_class, name")


class GoldenResult(msgspec.Struct, frozen=True):
    gear_class: str           # the test's class
    name: str                 # the test's name
    version: int              # the template version it ran against (0: none could be read)
    draft: bool               # ran against a draft
    passed: bool
    failure: str | None       # one line: the first difference, naming the test and the expectation
    row_ids: tuple[int, ...]  # rows whose lines the program emitted
    ran_rows: tuple[int, ...] # rows that ran (computed or emitted), from the trace: for coverage

    @property
    def label(self) -> str:
        return f"{self.gear_class}/{self.name}"

    def as_dict(self) -> dict:
        return {"class": self.gear_class, "name": self.name, "version": self.version, "draft": self.draft,
                "passed": self.passed, "failure": self.failure}


def load_tests(conn: Connection, classes: list[str] | None = None) -> list[GoldenTest]:
    rows = conn.execute(TESTS, {"all": classes is None, "classes": list(classes or [])}).fetchall()
    # mypy counts row[:6] (of unknown length) as filling every field, the last two as too many
    return [GoldenTest(*row[:6], tuple(row[6]), row[7]) for row in rows]   # type: ignore[call-arg]


def run_golden_tests(conn: Connection, classes: list[str] | None = None, draft: bool = True) -> list[GoldenResult]:
    """Every test of `classes` (None: all). draft=True tests each class's current rows (its draft,
    or its released version if it has none); False tests the released versions."""
    return [run_golden_test(conn, test, draft) for test in load_tests(conn, classes)]


def run_golden_test(conn: Connection, test: GoldenTest, draft: bool = True) -> GoldenResult:
    """One test: its program made in memory and checked against its expectations."""
    version, is_draft = _template_version(conn, test.gear_class, draft)
    try:
        planned, names = made_program(conn, test, draft)
    except EngineError as error:
        return GoldenResult(test.gear_class, test.name, version, is_draft, False,
                            f"test {test.label}: {_one_line(error)}", (), ())
    result = planned.result
    problem = first_difference(test.expect, Context(list(result.lines), names))
    return GoldenResult(test.gear_class, test.name, planned.template.version, planned.template.draft,
                        problem is None, None if problem is None else f"test {test.label}: {problem}",
                        _emitted(result.row_ids), ran_rows(result.trace))


def _template_version(conn: Connection, gear_class: str, draft: bool) -> tuple[int, bool]:
    """The version a test runs against, for its result line even when the run fails."""
    try:
        template = runnable_template(conn, gear_class, draft)
    except EngineError:
        return 0, draft
    return template.version, template.draft


def _emitted(row_ids) -> tuple[int, ...]:
    return tuple(sorted({row_id for row_id in row_ids if row_id >= 0}))


def ran_rows(trace: dict) -> tuple[int, ...]:
    """Rows whose statements ran or whose line was emitted."""
    return tuple(sorted(entry["row"] for entry in trace.get("rows", ())
                        if entry.get("calc") is True or entry.get("emit") is True))


def _one_line(error: Exception) -> str:
    return " ".join(str(error).split())
