"""Classes and releases on the web view (issue 32): the classes, each class's versions with their
states and releases, the impact of its current draft and its golden tests' results, each as
`engine template list | history`, `engine template release --dry-run` and `engine test --class`
print them with `--json` (the same library calls, the same keys: engine.release.shown).

A release is re-checked as it is shown (engine.release.recheck), as `engine template history` does:
a page says "gate passed" only of a release the engine's gate made whose re-check passes now
(design notes §10). The draft's impact proves each changed program (seconds for a class with many
stored jobs) and the golden tests make their programs: both run only when asked for, from a link."""
from __future__ import annotations

from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import Route

from ...errors import EngineError
from .pages import connection, page, refusal, wants_json

CLASS_EXISTS = "SELECT 1 FROM gear_class WHERE name = %s"
# The impact a version's (latest) release recorded, as the releasing session stated it.
STATED_IMPACT = "SELECT impact FROM template_release WHERE gear_class = %s AND version = %s ORDER BY id DESC LIMIT 1"


def classes_list(request: Request) -> Response:
    """Every class: `engine template list --json`."""
    from ...templates.store import class_records

    with connection(request) as conn:
        return page(request, "classes.html", {"classes": class_records(conn)})


def class_page(request: Request) -> Response:
    """A class's versions, their states and releases: `engine template history --json`; the page
    adds each release's line as the command prints it, the class's golden tests (not run), and its
    draft's version: the link to the draft's impact only when there is one (else the link answered
    400 "has no draft", the review of issue 32)."""
    from ...release.golden import load_tests
    from ...release.recheck import verdict
    from ...release.shown import release_text, version_json
    from ...templates.store import class_and_descendants

    name = request.path_params["name"]
    with connection(request) as conn:
        if not _exists(conn, name):
            return _unknown(request, name)
        entries = _history(conn, name)
        verdicts = {entry.version: verdict(conn, name, entry.release) for entry in entries if entry.release}
        data = {"class": name, "versions": [version_json(entry, verdicts.get(entry.version)) for entry in entries]}
        if wants_json(request):
            return page(request, "class.html", data)
        said = {entry.version: release_text(entry.release, verdicts[entry.version])
                for entry in entries if entry.release}
        tests = load_tests(conn, class_and_descendants(conn, name))
    draft = next((entry.version for entry in entries if entry.state == "draft"), None)
    return page(request, "class.html", {**data, "said": said, "golden_tests": tests, "draft": draft})


def version_page(request: Request) -> Response:
    """One version: its entry of `engine template history --json` (`version`), the rows it changed
    from the version stored before it (`diff`: `engine template diff --json`; None for the first)
    and the impact its release recorded as the releasing session stated it (`stated_impact`, never
    recomputed: the job ids it changed and failed for)."""
    from ...release.recheck import verdict
    from ...release.shown import release_text, version_json

    name, number = request.path_params["name"], request.path_params["version"]
    with connection(request) as conn:
        if not _exists(conn, name):
            return _unknown(request, name)
        entries = {entry.version: entry for entry in _history(conn, name)}
        if number not in entries:
            return refusal(request, f"class {name!r} has no version {number}; stored versions: "
                                    f"{', '.join(map(str, entries))}", 404)
        entry = entries[number]
        found = verdict(conn, name, entry.release) if entry.release else None
        data = {"class": name, "version": version_json(entry, found),
                "diff": _diff_before(conn, name, number, [v for v in entries if v < number]),
                "stated_impact": _stated_impact(conn, name, number)}
    said = release_text(entry.release, found) if entry.release and found else None
    return page(request, "version.html", data if wants_json(request) else {**data, "said": said})


def _history(conn, name: str):
    from ...templates.history import history

    return history(conn, name)


def _diff_before(conn, name: str, number: int, earlier: list[int]) -> dict | None:
    """`engine template diff --json` from the version stored before `number` (None: the first)."""
    from ...release.shown import diff_json
    from ...templates.history import diff, layout_change

    if not earlier:
        return None
    before = max(earlier)
    return diff_json(name, before, number, diff(conn, name, before, number), layout_change(conn, name, before, number))


def _stated_impact(conn, name: str, number: int) -> dict | None:
    found = conn.execute(STATED_IMPACT, (name, number)).fetchone()
    return None if found is None else found[0]


def draft_impact(request: Request) -> Response:
    """What releasing the class's draft would change, computed now: `engine template release
    --dry-run --json` (the gate, then every stored job made again with the draft and each changed
    program proved). A gate that refuses is answered with every problem, as the command lists them."""
    from ...release.gate import GateRefusal, release
    from ...release.shown import report_json

    name = request.path_params["name"]
    with connection(request) as conn:
        if not _exists(conn, name):
            return _unknown(request, name)
        try:
            report = release(conn, name, dry_run=True)
        except GateRefusal as refused:
            return page(request, "impact.html", {"class": name, "error": str(refused), "problems": refused.problems},
                        status=400)
        except EngineError as error:
            return refusal(request, str(error))
    return page(request, "impact.html", report_json(report))


def golden_results(request: Request) -> Response:
    """The golden tests of the class and its descendants, run now: `engine test --class NAME --json`
    (`?released=1`: against the released versions, as `--released`)."""
    from ...release.golden import run_golden_tests
    from ...release.recheck import refuse_golden_tests_at_a_plant
    from ...templates.store import class_and_descendants

    name = request.path_params["name"]
    released = request.query_params.get("released", "") not in ("", "0")
    with connection(request) as conn:
        if not _exists(conn, name):
            return _unknown(request, name)
        try:
            refuse_golden_tests_at_a_plant(conn)
        except EngineError as error:
            return refusal(request, str(error))
        results = run_golden_tests(conn, class_and_descendants(conn, name), draft=not released)
    failed = [result for result in results if not result.passed]
    data = {"passed": len(results) - len(failed), "failed": len(failed),
            "tests": [result.as_dict() for result in results]}
    if wants_json(request):
        return page(request, "golden.html", data)
    return page(request, "golden.html", {**data, "class": name, "released": released})


def _exists(conn, name: str) -> bool:
    return conn.execute(CLASS_EXISTS, (name,)).fetchone() is not None


def _unknown(request: Request, name: str) -> Response:
    return refusal(request, f"gear class {name!r} does not exist; see the classes (engine template list)", 404)


ROUTES = [
    Route("/classes", classes_list, name="classes"),
    Route("/classes/{name}", class_page, name="class"),
    Route("/classes/{name}/versions/{version:int}", version_page, name="class_version"),
    Route("/classes/{name}/impact", draft_impact, name="class_impact"),
    Route("/classes/{name}/tests", golden_results, name="class_tests"),
]
