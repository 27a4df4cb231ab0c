"""`engine template release`: the gate between a class's draft and the shop floor (issue 15).

A draft is released only if (1) every expression passes the static check (engine lint), (2) the
golden tests of the class and of its descendants pass against their drafts (engine test), and
(3) static analysis finds nothing (engine.templates.analysis). Any failure refuses the release
and names every row, column and test that failed. Then the impact: what the release changes in
the programs of the stored jobs (engine.release.impact). Not a dry run: the release is recorded
(release_template, which only engine_releaser may run) in the transaction that read the draft, so
what was checked is what is released."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
from psycopg.errors import InsufficientPrivilege
from psycopg.types.json import Jsonb

from ..db.connection import scalar
from ..errors import EngineError
from ..programs import all_models  # noqa: F401  (registers every model)
from ..templates.analysis import class_findings
from ..templates.history import WITHOUT_TESTS
from ..templates.lint import lint_class
from ..templates.store import class_and_descendants
from ..templates.versions import draft_template
from .impact import Impact, impact

if TYPE_CHECKING:
    from ..db.connection import Connection

RELEASER_ROLE = "engine_releaser"
RELEASE = "SELECT release_template(%s, %s, %s, %s, %s, %s, via => 'engine')"   # after the gate (§10)
MAY_RELEASE = ("SELECT current_user, has_function_privilege("
               "'release_template(text, integer, text, jsonb, jsonb, jsonb, text, text)', 'EXECUTE')")


class GateRefusal(EngineError):
    """The gate refused a release: `problems` lists every failed check, one line each."""

    def __init__(self, gear_class: str, version: int, problems: list[str]):
        self.problems = problems
        more = f" (and {len(problems) - 1} more, listed below)" if len(problems) > 1 else ""
        super().__init__(f"class {gear_class} v{version} not released: {problems[0]}{more}")


class ReleaseReport(msgspec.Struct):
    gear_class: str
    version: int
    hash: str
    dry_run: bool
    tests: list[dict]
    impact: Impact
    checks: dict
    release_id: int | None = None
    drafts_below: list[str] = []   # descendants whose drafts need their own release


def release(conn: Connection, gear_class: str, dry_run: bool = False, confirm=None, workers: int = 1,
            without_golden_tests: bool = False) -> ReleaseReport:
    """Gate, impact and (not a dry run) the release of the class's draft, in one transaction.
    `confirm(report)`, if given, is asked after the impact and before recording; False releases
    nothing. The impact proves the programs the draft changes in `workers` processes. A class
    with no golden test (nor its descendants) is refused unless `without_golden_tests`: the
    release then records that it was accepted so (checks, shown by `engine template history`)."""
    with conn.transaction():
        draft = draft_template(conn, gear_class)
        if not draft.draft:
            raise EngineError(f"class {gear_class} has no draft: version {draft.version} is released; edit its "
                              "rows (template_view, engine template import) to make one")
        if not dry_run:
            _require_releaser(conn)
        tests, checks = gate(conn, gear_class, draft, without_golden_tests)
        report = ReleaseReport(gear_class, draft.version, draft.hash, dry_run, tests, impact(conn, gear_class, workers),
                               checks, drafts_below=drafts_below(conn, gear_class))
        refuse_broken_jobs(gear_class, draft.version, report.impact)
        if not dry_run and (confirm is None or confirm(report)):
            report.release_id = _record(conn, report)
    return report


def refuse_broken_jobs(gear_class: str, version: int, found: Impact) -> None:
    """A draft that makes no program for a stored job the released version makes one for (a turning
    row emitting a rapid through the part, say) would stop that job at the machine: refused, each
    job named. A job that fails with the released version too is an older problem: listed, not refused."""
    broken = [failure for failure in found.failures if failure.released_makes]
    if broken:
        raise GateRefusal(gear_class, version, [f"stored job {failure.job_id} ({failure.gear_class}) gets a program "
                                                f"from the released version but none from the draft: {failure.error}"
                                                for failure in broken])


def _require_releaser(conn: Connection) -> None:
    found = conn.execute(MAY_RELEASE).fetchone()
    assert found is not None   # a SELECT without FROM returns its one row
    role, allowed = found
    if not allowed:
        raise EngineError(_role_needed(role))


def _role_needed(role: str) -> str:
    return f"releasing a template needs the role {RELEASER_ROLE}; {role} may not (nothing released)"


def gate(conn: Connection, gear_class: str, draft, without_golden_tests: bool = False) -> tuple[list[dict], dict]:
    """The three checks; GateRefusal naming every failure. Returns the tests run and the checks.
    No golden test at all is a failure too (a gate that ran nothing proved nothing), unless the
    caller accepts it (`without_golden_tests`), which the checks record."""
    lint_problems = [str(problem) for problem in lint_class(conn, gear_class)]
    results = _golden_results(conn, gear_class)
    problems = lint_problems + [f"golden {result.failure}"
                                for result in results if not result.passed]
    if not results and not without_golden_tests:
        problems.append(no_tests_problem(gear_class))
    if not lint_problems:   # rows that do not compile cannot be analysed: lint named them
        problems += [str(finding) for finding in class_findings(conn, gear_class, draft)]
    if problems:
        raise GateRefusal(gear_class, draft.version, problems)
    tests = [{"class": result.gear_class, "name": result.name, "passed": result.passed} for result in results]
    checks = {"lint": "passed", "analysis": "no finding", "golden_tests": len(tests)}
    return tests, {**checks, WITHOUT_TESTS: True} if not tests else checks


def no_tests_problem(gear_class: str) -> str:
    return (f"no golden test for class {gear_class} or its descendants: add one from a proven program "
            "(engine test add --from-program ID), or accept releasing untested with --without-golden-tests")


def _golden_results(conn: Connection, gear_class: str) -> list:
    from .golden import run_golden_tests  # the golden tests' language (engine test)

    return run_golden_tests(conn, class_and_descendants(conn, gear_class), draft=True)


# Classes below (not the class itself) with rows whose current version is not the released one.
DRAFTS_BELOW = """
SELECT g.name FROM classes_and_below(ARRAY[%(class)s]) b JOIN gear_class g ON g.name = b.name
WHERE g.name <> %(class)s AND g.template_version IS DISTINCT FROM released_version(g.name)
  AND EXISTS (SELECT 1 FROM assembled_row r WHERE r.gear_class = g.name)
ORDER BY g.name"""


def drafts_below(conn: Connection, gear_class: str) -> list[str]:
    """The descendants whose current rows are not released: the class's change gave them drafts
    (or they had their own), which need their own release. An inner node without rows has nothing
    to release."""
    return [row[0] for row in conn.execute(DRAFTS_BELOW, {"class": gear_class})]


def _record(conn: Connection, report: ReleaseReport) -> int:
    try:
        with conn.transaction():
            return scalar(conn.execute(RELEASE, (report.gear_class, report.version, report.hash,
                                                 Jsonb(report.tests), Jsonb(report.impact.summary()),
                                                 Jsonb(report.checks))))
    except InsufficientPrivilege:
        raise EngineError(_role_needed(scalar(conn.execute("SELECT current_user")))) from None
