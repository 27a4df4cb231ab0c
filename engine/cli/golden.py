"""`engine test`: the golden tests of the templates (template_test), and their coverage.
(Named golden.py, not tests.py, so pytest does not collect it.)"""
from __future__ import annotations

from typing import TYPE_CHECKING

import click

from ..errors import EngineError
from .context import connection, emit_json

if TYPE_CHECKING:
    from ..db.connection import Connection


@click.group("test", invoke_without_command=True)
@click.option("--class", "gear_class", help="Only this class's tests and its descendants'.")
@click.option("--released", is_flag=True, help="Test the released versions, not the current rows (drafts).")
@click.option("--coverage", "show_coverage", is_flag=True,
              help="List the rows no test and no program stored lately emitted or ran.")
@click.option("--days", type=click.IntRange(min=0), default=30, show_default=True,
              help="With --coverage: programs stored in the last DAYS days count.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object on one line.")
@click.pass_context
def test_command(ctx, gear_class, released, show_coverage, days, as_json):
    """Run the golden tests of the templates: each makes its program in memory (nothing stored)
    and checks its expectations. One line per test, `PASS spur/gear42-default v3 (draft)` or
    `FAIL … <first difference>`, then a summary. Exit 1 if any test fails or none exists.

    The expectations are `line: M30`, `no line: M8`, `match: REGEX`, `no match: REGEX`,
    `last X = (df2 + da0)/2 ± 0.01` and the like (docs/guide/release-and-golden-tests.md).

    `engine test add --from-program ID` makes a test of a proven stored program.

    At a plant the tests are refused in one line: they run on the head office's gears, which a
    plant does not receive; each release's tests ran at the head office (engine template history).

    Example: engine test --class spur --json
    """
    from ..templates.store import class_and_descendants

    if ctx.invoked_subcommand is not None:
        return
    with connection(ctx) as conn:
        classes = class_and_descendants(conn, gear_class) if gear_class else None
        if show_coverage:
            _report_coverage(conn, classes, days, as_json)
            return
        _report_tests(conn, classes, gear_class, released, as_json)


@test_command.command("add")
@click.option("--from-program", "program_id", type=click.IntRange(min=1), required=True,
              help="A stored program proved by the verifier and the simulation (see engine programs list).")
@click.option("--name", help="The test's name (letters, digits, _ . -); default program<ID>.")
@click.pass_context
def test_add(ctx, program_id, name):
    """Add a golden test of the program's class whose expectations are the program's lines (the
    lineage line and the lines showing the template's version left out) and its numeric properties
    (line count, G0/G1 blocks, each axis's range, the EGON ratio). The test runs the program's job
    parameters on its machine; it is run once before it is stored, so a program the class's
    current rows no longer make is refused, naming the first difference. Needs engine_editor.

    Example: engine test add --from-program 12 --name gear42-shop
    """
    from ..release.from_program import add_from_program

    with connection(ctx) as conn:
        added = add_from_program(conn, program_id, name)
    left_out = f", {added.left_out} line(s) showing the template version left out" if added.left_out else ""
    click.echo(f"added golden test {added.gear_class}/{added.name} (id {added.id}): "
               f"{added.expectations} expectation(s) from program {program_id}{left_out}")


def _report_tests(conn: Connection, classes, gear_class, released, as_json) -> None:
    from ..release.golden import run_golden_tests
    from ..release.recheck import refuse_golden_tests_at_a_plant

    refuse_golden_tests_at_a_plant(conn)   # issue 33: a plant's gear 42 is not the head office's gear 42

    results = run_golden_tests(conn, classes, draft=not released)
    failed = [result for result in results if not result.passed]
    if as_json:
        emit_json({"passed": len(results) - len(failed), "failed": len(failed),
                   "tests": [result.as_dict() for result in results]})
    else:
        for result in results:
            click.echo(_result_line(result))
        click.echo(f"{len(results) - len(failed)} passed, {len(failed)} failed")
    if not results:
        raise EngineError(f"no golden tests{f' for class {gear_class} (or its descendants)' if gear_class else ''}; "
                          "add one with engine test add --from-program ID")
    if failed:
        raise click.exceptions.Exit(1)


def _result_line(result) -> str:
    state = " (draft)" if result.draft else ""
    if result.passed:
        return f"PASS {result.label} v{result.version}{state}"
    failure = result.failure.removeprefix(f"test {result.label}: ")
    return f"FAIL {result.label} v{result.version}{state}: {failure}"


def _report_coverage(conn: Connection, classes, days, as_json) -> None:
    from ..release.coverage import coverage

    rows = coverage(conn, days, classes)
    if as_json:
        emit_json({"days": days, "uncovered": [row.as_dict() for row in rows]})
        return
    for row in rows:
        click.echo(f"{row.gear_class} row {row.row_id} {row.t}: {row.o if row.o is not None else '(computes only)'}")
    click.echo(f"{len(rows)} rows not covered by a golden test or a program stored in the last {days} days")
