"""A release re-checked where it is shown (issue 26, finding 7; design notes §10, threat model).

template_release keeps what the caller of release_template states (the tests it ran, the impact)
and how it says it released (released_via): both are claims of the releasing login, since the
database cannot run the gate and the engine calls it as that same login. What the database takes
itself is the golden tests of the class and its descendants at the release (golden_tests, each
with its class's version then). So a screen re-runs the gate's checks of the released version:
lint and static analysis of its stored rows, and the recorded golden tests against the stored
versions they ran against (milliseconds each). "gate passed" is said only of a release the
engine's gate made whose re-check passes; anything else says what is true."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..programs import all_models  # noqa: F401  (registers every model)
from ..templates.analysis import class_findings
from ..templates.lint import lint_class
from ..templates.versions import pinned_templates, stored_template
from .golden import load_tests, run_golden_test
from .golden_runs import GoldenTest

if TYPE_CHECKING:
    from ..db.connection import Connection
    from ..templates.rows import Template

# released_via → how a screen names a release that is not the engine gate's (its own words)
NOT_THE_GATE = {"seed": "by engine seed, not through the engine's gate",
                "sql": "released by hand from SQL by {login}, not through the engine's gate: the results it "
                       "states were not checked by the engine",
                "unrecorded": "how it was released is not recorded (before migration 0026): not shown as the "
                              "engine's gate"}


class Recheck(msgspec.Struct, frozen=True):
    """The gate's checks of a released version, run again now."""
    tests: int                  # golden tests re-run
    problems: tuple[str, ...]   # every failure: lint, analysis, golden test (one line each)
    recorded: bool              # the tests are those recorded with the release (False: before 0026, today's)

    @property
    def passed(self) -> bool:
        return not self.problems


class Verdict(msgspec.Struct, frozen=True):
    gate: str        # passed, mismatch (recorded as the gate's, fails now), not run (not the gate's release)
    said: str        # one line for the screen
    recheck: Recheck

    def as_json(self) -> dict:
        return {"gate": self.gate, "said": self.said,
                "recheck": {"passed": self.recheck.passed, "tests": self.recheck.tests,
                            "problems": list(self.recheck.problems), "recorded_tests": self.recheck.recorded}}


def verdict(conn: Connection, gear_class: str, release) -> Verdict:
    """What a screen says of `release` (engine.templates.history.ReleaseEntry of the class)."""
    found = recheck(conn, gear_class, release.version, release.golden_tests)
    return Verdict(*_said(release.released_via, release.released_by, found), found)


def _said(via: str, login: str, found: Recheck) -> tuple[str, str]:
    now = _recheck_text(found)
    if via == "engine":
        if found.passed:
            return "passed", f"gate passed (as {login} recorded it; re-checked now: {now})"
        return "mismatch", f"MISMATCH: recorded as passed by the engine's gate; re-checked now: {now}"
    return "not run", f"{NOT_THE_GATE[via].format(login=login)}; re-checked now: {now}"


def _recheck_text(found: Recheck) -> str:
    tests = f"{found.tests} golden test(s)" + ("" if found.recorded else " (today's; none recorded)")
    if found.passed:
        return f"lint, {tests}, static analysis pass"
    more = f" (and {len(found.problems) - 1} more)" if len(found.problems) > 1 else ""
    return f"fails: {found.problems[0]}{more}"


def recheck(conn: Connection, gear_class: str, version: int, golden_tests: list[dict] | None) -> Recheck:
    """Lint and analysis of the class's stored `version`, and the golden tests recorded with its
    release (before migration 0026: the class's tests now) against the versions they ran on."""
    try:
        template = stored_template(conn, gear_class, version)
    except EngineError as error:
        return Recheck(0, (str(error),), golden_tests is not None)
    problems = _static_problems(conn, gear_class, template)
    tests = _recorded_tests(golden_tests) if golden_tests is not None else \
        [(test, version) for test in load_tests(conn, [gear_class])]
    problems += [problem for test, ran_on in tests if (problem := _golden_problem(conn, test, ran_on))]
    return Recheck(len(tests), tuple(problems), golden_tests is not None)


def _static_problems(conn: Connection, gear_class: str, template: Template) -> list[str]:
    """The gate's lint, then (rows that compile) its static analysis, of the stored version."""
    problems = [str(problem) for problem in lint_class(conn, gear_class, template)]
    return problems or [str(finding) for finding in class_findings(conn, gear_class, template)]


def _recorded_tests(golden_tests: list[dict]) -> list[tuple[GoldenTest, int]]:
    return [(GoldenTest(test["id"], test["class"], test["name"], test["gear_id"], test["params"],
                        test["choices"], tuple(test["expect"]), test.get("description", "")), test["version"])
            for test in golden_tests]


def _golden_problem(conn: Connection, test: GoldenTest, version: int) -> str | None:
    """The test run against the stored version of its class it ran on at the release."""
    try:
        template = stored_template(conn, test.gear_class, version)
    except EngineError as error:
        return f"golden test {test.label}: {error}"
    with pinned_templates({test.gear_class: template}):
        result = run_golden_test(conn, test, draft=False)
    return None if result.passed else f"golden {result.failure}"
