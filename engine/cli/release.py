"""`engine template release`: the gate, the impact and the release of a class's draft."""
from __future__ import annotations

import click

from .context import connection, emit_json

SHOWN_FAILURES = 5   # jobs the draft fails for, listed by the text output (all with --json)


@click.command("release")
@click.option("--class", "gear_class", required=True, help="Gear class whose draft is released.")
@click.option("--dry-run", is_flag=True, help="Run the gate and show the impact; release nothing.")
@click.option("--yes", is_flag=True, help="Release without asking (after the gate and the impact).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object, every diff included.")
@click.option("--workers", type=click.IntRange(1, 64), default=1, show_default=True,
              help="Make the stored jobs' programs again and prove the changed ones (verifier and simulation) "
                   "in this many processes.")
@click.option("--without-golden-tests", is_flag=True,
              help="Accept releasing a class that has no golden test (nor its descendants); the release "
                   "history says it was accepted so.")
@click.pass_context
def template_release(ctx, gear_class, dry_run, yes, as_json, workers, without_golden_tests):
    """Release the class's draft to the shop floor: refused, naming every row, column and test that
    failed, unless engine lint, the golden tests of the class and its descendants and the static
    analysis pass; a class with no golden test (nor its descendants) is refused unless
    --without-golden-tests accepts it, which the release records (engine template history says so).
    Shows how many stored programs the release changes and the first diffs, each changed program
    proved by the verifier and the simulation, then asks (unless --yes). Needs the role
    engine_releaser.

    Example: engine template release --class spur --dry-run
    """
    from ..release.gate import release
    from ..release.impact import DIFFS_SHOWN
    from ..release.shown import report_json

    def confirm(report) -> bool:
        if yes:
            return True
        if not as_json:
            _show(report, DIFFS_SHOWN)
        return click.confirm(f"release class {report.gear_class} v{report.version}?", err=True)

    from ..plants.guard import refuse_at_a_plant

    with connection(ctx) as conn:
        refuse_at_a_plant(conn, f"template release --class {gear_class}")
        report = release(conn, gear_class, dry_run=dry_run, confirm=confirm, workers=workers,
                         without_golden_tests=without_golden_tests)
    if as_json:
        return emit_json(report_json(report))
    if dry_run or yes:
        _show(report, DIFFS_SHOWN)
    click.echo(_outcome(report))


def _show(report, diffs_shown: int) -> None:
    impact = report.impact
    click.echo(f"class {report.gear_class} v{report.version} ({report.hash[:8]}): gate passed: lint, "
               f"{_tests_said(report)}, static analysis")
    click.echo(f"impact: {impact.jobs} stored job(s) of {report.gear_class} and its descendants, "
               f"{impact.changed} program(s) change, {len(impact.failures)} fail with the draft; "
               f"{impact.proved} changed program(s) proved (machine verifier and simulation){impact.plants_said()}")
    for change in impact.layouts.values():
        click.echo(change.said())
    for failure in impact.failures[:SHOWN_FAILURES]:
        click.echo(f"  job {failure.job_id} ({failure.gear_class}): {failure.error}")
    for diff in impact.diffs[:diffs_shown]:
        click.echo(f"job {diff.job_id} ({diff.gear_class}):\n{diff.diff}")
    if len(impact.diffs) > diffs_shown:
        click.echo(f"… {len(impact.diffs) - diffs_shown} more changed program(s) (all with --json)")


def _tests_said(report) -> str:
    if report.tests:
        return f"{len(report.tests)} golden test(s)"
    return "NO golden test (accepted with --without-golden-tests)"


def _outcome(report) -> str:
    below = (f"; descendants with drafts that need their own release: {', '.join(report.drafts_below)}"
             if report.drafts_below else "")
    if report.release_id is not None:
        return f"released class {report.gear_class} v{report.version} (release {report.release_id}){below}"
    what = "dry run" if report.dry_run else "not confirmed"
    return f"{what}: nothing released{below}"
