"""`engine refactor` (and its intend / intents / unintend) and `engine template shared`: thin
shells over engine.library.refactor and engine.library.intended."""
from __future__ import annotations

import click

from .context import connection, emit_json
from .intended import intend_command, intents_command, unintend_command
from .output import Column, emit_list, list_options
from .progress import progress_bar


@click.group("refactor", invoke_without_command=True)
@click.option("--threshold", default=0.8, show_default=True, type=click.FloatRange(0, 1, min_open=True),
              help="Report line pairs of one module type with this similarity or more (Sim < 1).")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: changed, components_before, components_after, shared, new, "
                   "known, intended, families (counts) and near_duplicates (per entry: key, new, kind, t, sim; "
                   "a pair: texts a and b, members_a/members_b, uses_a/uses_b and the first 10 class:row uses "
                   "of each; a family of lines differing only in the block number: members, uses, rows; "
                   "template_view has them all).")
@click.pass_context
def refactor_command(ctx, threshold, as_json):
    """Merge identical component bodies and report near-duplicate lines to unify.

    One transaction: every class's assembled template stays exactly as it was (checked
    before commit, else nothing is changed and the class is named), and a second run
    changes nothing. Instantiations go on meanwhile; template writers wait. Meant to run
    every night (docs/guide/refactor-and-library.md: cron or a systemd timer); exit code 0 also when nothing changed.

    Block numbers are left out: lines that differ only in theirs are one family, listed
    once. Pairs no earlier run listed come first, marked new; pairs marked intended (the
    subcommands) are not listed, only counted. Each pair and family has a key for `intend`.

    Example: engine refactor --threshold 0.85 --json >> refactor.jsonl
    """
    if ctx.invoked_subcommand is not None:
        return
    from ..library.refactor import refactor

    with connection(ctx) as conn, progress_bar("refactor") as progress:
        report = refactor(conn, threshold, progress)
    if as_json:
        emit_json(report.as_dict())
    else:
        _print_report(report)


for _command in (intend_command, intents_command, unintend_command):
    refactor_command.add_command(_command)


def _print_report(report) -> None:
    merged = report.components_before - report.components_after
    state = (f"merged or removed {merged} component(s)" if report.changed
             else "nothing to merge (the library was already stored once)")
    click.echo(f"refactor: {state}; components {report.components_before} -> "
               f"{report.components_after}, {report.shared} used by two or more classes; "
               f"every class's assembled template unchanged. {len(report.near_duplicates) - report.families} "
               f"near-duplicate pair(s) with similarity >= {report.threshold:g} and {report.families} "
               f"family(ies) of lines differing only in the block number to unify by hand "
               f"({report.new} new, {report.known} known; {report.intended} marked intended, not listed).")
    for entry in report.near_duplicates:
        (_print_family if entry["kind"] == "family" else _print_pair)(entry)


def _print_pair(pair: dict) -> None:
    click.echo(f"\n  {'NEW ' if pair['new'] else ''}{pair['key']}  {pair['t']}  Sim {pair['sim']:.3f}")
    for side in "ab":
        others = len(pair[f"members_{side}"]) - 1
        family = f", and {others} more line(s) differing only in the block number" if others else ""
        click.echo(f"    {pair[side]}   ({_uses(pair[f'rows_{side}'], pair[f'uses_{side}'])}{family})")


def _print_family(family: dict) -> None:
    """The family's members (the first USES_LISTED of them) and where they are used."""
    members = family["members"]
    click.echo(f"\n  {'NEW ' if family['new'] else ''}{family['key']}  {family['t']}  {len(members)} lines "
               f"differing only in the block number ({_uses(family['rows'], family['uses'])})")
    for text in members[:USES_LISTED]:
        click.echo(f"    {text}")
    if len(members) > USES_LISTED:
        click.echo(f"    and {len(members) - USES_LISTED} more")


USES_LISTED = 10   # members of a family printed; --json lists them all


def _uses(rows, count: int) -> str:
    listed = ", ".join(f"{gear_class}:{row_id}" for gear_class, row_id in rows)
    return listed + (f" and {count - len(rows)} more" if count > len(rows) else "")


SHARED_COLUMNS = (Column("row", "row_id"), Column("t", "t"), Column("from", "inherited_from"),
                  Column("shared with", "shared_with", lambda classes: ", ".join(classes) or "-"), Column("o", "o"))


@click.command("shared")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@list_options("rows")
@click.pass_context
def template_shared(ctx, gear_class, output):
    """Per row of the class's template: shared with other classes (which) or its own."""
    from ..library.refactor import shared_rows

    with connection(ctx) as conn:
        rows = shared_rows(conn, gear_class)
    if output:
        records = [{"class": gear_class, "row_id": row.id, "t": row.t, "o": row.o, "inherited_from": row.inherited_from,
                    "shared_with": list(row.shared_with)} for row in rows]
        return emit_list(output, "rows", SHARED_COLUMNS, records)
    for row in rows:
        where = "own" if row.inherited_from == gear_class else f"inherited from {row.inherited_from}"
        use = (f"shared with {len(row.shared_with)} class(es): {', '.join(row.shared_with)}"
               if row.shared_with else "used by this class only")
        click.echo(f"{row.id:6} {row.t:9} {where:24} {use}  {row.o or ''}")
