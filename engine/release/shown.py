"""How a class's versions and releases are shown: the one line and the JSON that `engine template
history` prints and the web view of `engine serve` shows (issue 32), from one place, so a page
says of a release exactly what the command says. What the releasing session stated is said to be
stated; "gate passed" comes only from the re-check (engine.release.recheck, design notes §10)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..nc.layout import ENDING_NAMES

if TYPE_CHECKING:
    from ..nc.layout import NcLayout
    from ..templates.history import ReleaseEntry, RowChange, VersionEntry
    from .gate import ReleaseReport
    from .recheck import Verdict


def release_text(release: ReleaseEntry, verdict: Verdict) -> str:
    """Who released, and what is true of the gate (engine.release.recheck); what the releasing
    session states is said to be stated: the tests when the gate did not make the release, the impact
    always (the database cannot recompute it, and `via` is the releasing login's own claim)."""
    impact = ("" if release.jobs is None else
              f"; impact as the releasing session stated it (not re-checked): {release.changed} of {release.jobs} "
              f"stored job(s) changed{_failed_text(release.failed)}")
    stated = ("" if verdict.gate == "passed" or not release.tests
              else f"; it states {release.tests} golden test(s) passed")
    note = f" ({release.note})" if release.note else ""
    return (f"released {release.released_at:%Y-%m-%d %H:%M:%S} by {release.released_by} as {release.role}: "
            f"{_untested_text(release)}{verdict.said}{stated}{impact}{note}")


def _untested_text(release: ReleaseEntry) -> str:
    """A release with no golden test, accepted so on the command line (the checks it recorded)."""
    return "WITHOUT GOLDEN TESTS (accepted with --without-golden-tests); " if release.without_tests else ""


def _failed_text(failed: int | None) -> str:
    """Stored jobs the released version made no program for (the impact's refusals)."""
    return f", {failed} job(s) fail with it" if failed else ""


def version_json(entry: VersionEntry, verdict: Verdict | None) -> dict:
    """One version of `engine template history --json`."""
    return {"version": entry.version, "created_at": entry.created_at.isoformat(), "created_by": entry.created_by,
            "rows": entry.rows, "state": entry.state, "release": release_json(entry.release, verdict),
            "changes": [{"row_id": row_id, "operation": operation} for row_id, operation in entry.changes],
            "line_ending": ENDING_NAMES[entry.layout.line_ending], "final_newline": entry.layout.final_newline}


def release_json(release: ReleaseEntry | None, verdict: Verdict | None) -> dict | None:
    """`tests`, `changed`, `jobs`, `failed`: what the releasing session stated (jobs whose program the
    release changed, of the stored jobs, and those it made none for); `golden_tests`: the tests the
    database recorded with the release (class, name, the class's version they ran on; None before
    migration 0026); `gate`: passed only for the engine's gate's release that passes its re-check
    now (`recheck`)."""
    if release is None or verdict is None:
        return None
    return {"released_at": release.released_at.isoformat(), "released_by": release.released_by,
            "role": release.role, "released_via": release.released_via, "tests": release.tests,
            "changed": release.changed, "jobs": release.jobs, "failed": release.failed, "note": release.note,
            "accepted_without_golden_tests": release.without_tests,
            "golden_tests": recorded_tests(release),
            **verdict.as_json()}


def recorded_tests(release: ReleaseEntry) -> list[dict] | None:
    """The golden tests recorded with the release: which tests guarded it (None: not recorded)."""
    if release.golden_tests is None:
        return None
    return [{"class": test["class"], "name": test["name"], "version": test["version"]}
            for test in release.golden_tests]


def report_json(report: ReleaseReport) -> dict:
    """`engine template release --json` (and `--dry-run --json`: the draft's impact)."""
    impact = report.impact
    return {"class": report.gear_class, "version": report.version, "hash": report.hash,
            "dry_run": report.dry_run, "released": report.release_id is not None, "release_id": report.release_id,
            "tests": report.tests, "checks": report.checks, "drafts_below": report.drafts_below,
            "impact": {"jobs": impact.jobs, "changed": impact.changed, "proved": impact.proved,
                       "failures": [{"job_id": f.job_id, "class": f.gear_class, "error": f.error}
                                    for f in impact.failures],
                       "diffs": [{"job_id": d.job_id, "class": d.gear_class, "diff": d.diff}
                                 for d in impact.diffs],
                       "layout": [change.as_json() for change in impact.layouts.values()],
                       "plants": impact.plants_json(), "plants_said": impact.plants_sentence()}}


def diff_json(gear_class: str, from_version: int, to_version: int, changes: list[RowChange],
              relaid: tuple[NcLayout, NcLayout] | None) -> dict:
    """`engine template diff --json`: the rows added, removed and changed between two versions, and
    the layout if it changed."""
    return {"class": gear_class, "from": from_version, "to": to_version,
            "changes": [{"row_id": c.row_id, "kind": c.kind, "old": c.old, "new": c.new} for c in changes],
            "layout": relaid and {"old": relaid[0].said, "new": relaid[1].said}}
