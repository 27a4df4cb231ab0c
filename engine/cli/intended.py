"""`engine refactor intend | intents | unintend`: thin shells over engine.library.intended."""
from __future__ import annotations

import csv
import sys

import click

from .context import connection, emit_json

INTENT_HEADINGS = ("key", "t", "a", "b", "why", "marked_by", "marked_role", "marked_at")


@click.command("intend")
@click.argument("key", required=False)
@click.option("--a", "text_a", metavar="TEXT", help="One line text of the pair (its o expression, as reported).")
@click.option("--b", "text_b", metavar="TEXT", help="The other line text of the pair.")
@click.option("--type", "module_type", metavar="T", help="The module type, if both texts are lines of several.")
@click.option("--why", required=True, help="Why the two lines stay different (stored with who and when).")
@click.pass_context
def intend_command(ctx, key, text_a, text_b, module_type, why):
    """Mark a near-duplicate pair intended: the nightly report no longer lists it, only counts it.

    Name the pair by the KEY the refactor report prints, or by both texts (--a, --b).
    Who marked it (login and role), why and when are stored.

    Example: engine refactor intend 3f9c01a2b7de --why "helical coupling needs the differential"
    """
    from ..library.intended import intend

    texts = (text_a, text_b) if text_a is not None or text_b is not None else None
    with connection(ctx) as conn:
        mark = intend(conn, why, key, texts, module_type)
    click.echo(f"marked intended: {mark.key}  {mark.t}  {mark.a}  |  {mark.b}  (by {mark.marked_by} "
               f"as {mark.marked_role}: {mark.why})")


@click.command("intents")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {intents: [{key, t, a, b, why, ...}]}.")
@click.option("--csv", "as_csv", is_flag=True, help="Print CSV with a header line: " + ",".join(INTENT_HEADINGS) + ".")
@click.pass_context
def intents_command(ctx, as_json, as_csv):
    """List the near-duplicate pairs marked intended, oldest first, with who, why and when.

    Example: engine refactor intents --csv > intended.csv
    """
    from ..library.intended import intents

    if as_json and as_csv:
        raise click.UsageError("--json and --csv exclude each other; give one")
    with connection(ctx) as conn:
        marks = [mark.as_dict() for mark in intents(conn)]
    if as_json:
        emit_json({"intents": marks})
    elif as_csv:
        _write_csv(marks)
    else:
        _print_marks(marks)


def _write_csv(marks: list[dict]) -> None:
    writer = csv.DictWriter(sys.stdout, fieldnames=INTENT_HEADINGS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(marks)


def _print_marks(marks: list[dict]) -> None:
    if not marks:
        click.echo("no near-duplicate pair is marked intended")
    for mark in marks:
        click.echo(f"{mark['key']}  {mark['t']}  marked {mark['marked_at']} by {mark['marked_by']} "
                   f"as {mark['marked_role']}: {mark['why']}")
        click.echo(f"    {mark['a']}")
        click.echo(f"    {mark['b']}")


@click.command("unintend")
@click.argument("key")
@click.pass_context
def unintend_command(ctx, key):
    """Withdraw a pair's intended mark: the next refactor run lists the pair again.

    The mark stays on record (who withdrew it, when) in near_duplicate_intended.

    Example: engine refactor unintend 3f9c01a2b7de
    """
    from ..library.intended import unintend

    with connection(ctx) as conn:
        mark = unintend(conn, key)
    click.echo(f"withdrawn: {mark.key}  {mark.t}  {mark.a}  |  {mark.b}")
