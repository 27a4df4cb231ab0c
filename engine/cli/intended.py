"""`engine refactor intend | intents | unintend`: thin shells over engine.library.intended."""
from __future__ import annotations

import click

from .context import connection
from .output import Column, emit_list, list_options

INTENT_COLUMNS = tuple(Column(key, key) for key in ("key", "t", "a", "b", "why", "marked_by", "marked_role",
                                                     "marked_at"))


@click.command("intend")
@click.argument("key", required=False)
@click.option("--a", "text_a", metavar="TEXT", help="One line text of the pair (its o expression, as reported).")
@click.option("--b", "text_b", metavar="TEXT", help="The other line text of the pair.")
@click.option("--type", "module_type", metavar="T", help="The module type, if both texts are lines of several.")
@click.option("--why", required=True, help="Why the two lines stay different (stored with who and when).")
@click.pass_context
def intend_command(ctx, key, text_a, text_b, module_type, why):
    """Mark a near-duplicate pair intended: the nightly report no longer lists it, only counts it.

    Name the pair by the KEY the refactor report prints, or by both texts (--a, --b); a
    family of lines differing only in the block number by its KEY or two of its lines.
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
@list_options("intents")
@click.pass_context
def intents_command(ctx, output):
    """List the near-duplicate pairs marked intended, oldest first, with who, why and when.

    Example: engine refactor intents --csv > intended.csv
    """
    from ..library.intended import intents

    with connection(ctx) as conn:
        marks = [mark.as_dict() for mark in intents(conn)]
    emit_list(output, "intents", INTENT_COLUMNS, marks)


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
