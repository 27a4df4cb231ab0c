"""A release re-checked where it is shown (issue 26, finding 7; design notes §10, threat model).

template_release keeps what the caller of release_template states (the tests it ran, the impact)
and how it says it released (released_via): both are claims of the releasing login, since the
database cannot run the gate and the engine calls it as that same login. What the database takes
itself is the golden tests of the class and its descendants at the release (golden_tests, each
with its class's version then). So a screen re-runs the gate's checks of the released version:
lint and static analysis of its stored rows, and the recorded golden tests against the stored
versions they ran against (milliseconds each). "gate passed" is said only of a release the
engine's gate made whose re-check passes; anything else says what is true.

At a plant (issue 33, docs/design.md §12) a release is the head office's: its golden tests ran there,
on the head office's gears and draft versions, which are not replicated (a plant's gear of the same
id is another gear). So a plant re-checks what it holds, the lint and static analysis of the
released rows, and says the golden tests ran at the head office, never "failed" here."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..db.origin import this_plant
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
    gate: str        # passed, mismatch (recorded as the gate's, fails now), not run (not the gate's release),
    #                  head office (at a plant: its golden tests ran there, not re-run here)
    said: str        # one line for the screen
    recheck: Recheck

    def as_json(self) -> dict:
        return {"gate": self.gate, "said": self.said,
                "recheck": {"passed": self.recheck.passed, "tests": self.recheck.tests,
                            "problems": list(self.recheck.problems), "recorded_tests": self.recheck.recorded}}


def verdict(conn: Connection, gear_class: str, release) -> Verdict:
    """What a screen says of `release` (engine.templates.history.ReleaseEntry of the class)."""
    if this_plant(conn) > 0:
        return _at_a_plant(conn, gear_class, release)
    found = recheck(conn, gear_class, release.version, release.golden_tests)
    return Verdict(*_said(release.released_via, release.released_by, found), found)


AT_THE_HEAD_OFFICE = "golden test(s) ran there; not re-checked here (their gears are the head office's)"


def _at_a_plant(conn: Connection, gear_class: str, release) -> Verdict:
    """A release received from the head office: its static checks re-run on the rows replicated
    here, its golden tests said to be the head office's."""
    try:
        problems = tuple(_static_problems(conn, gear_class, stored_template(conn, gear_class, release.version)))
    except EngineError as error:
        problems = (str(error),)
    found = Recheck(0, problems, release.golden_tests is not None)
    how = "through the engine's gate" if release.released_via == "engine" else \
        NOT_THE_GATE[release.released_via].format(login=release.released_by)
    tests = len(release.golden_tests) if release.golden_tests is not None else release.tests or 0
    here = "lint and static analysis of its rows pass" if found.passed else \
        f"its rows fail: {problems[0]}" + (f" (and {len(problems) - 1} more)" if len(problems) > 1 else "")
    return Verdict("head office", f"released at the head office ({how}); its {tests} {AT_THE_HEAD_OFFICE}; "
                                  f"re-checked here: {here}", found)


def refuse_golden_tests_at_a_plant(conn: Connection) -> None:
    """EngineError (one line) at a plant: golden tests run on the head office's gears and drafts,
    which a plant does not receive (its gear of the same id is its own, another gear)."""
    plant = this_plant(conn)
    if plant > 0:
        raise EngineError(f"this database is plant {plant}; the golden tests run on the head office's gears and "
                          "drafts, which are not replicated here (a gear of the same id here is the plant's own): "
                          "they ran at the head office when each version was released (engine template history "
                          "says so); run them there")


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
