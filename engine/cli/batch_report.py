"""What `engine instantiate` says of a batch (issue 31): a batch of 3,000 gears printed 1,483
`note:` lines and no summary, burying its result. Now its notes are counted by kind (the kind each
note was given where it was made: engine.notes), the first few of each kind shown, and one summary
line says what was stored, skipped and noted; --quiet prints that line alone, --json keeps every
note."""
from __future__ import annotations

from collections import Counter

import click

from ..notes import NOTE_KINDS, kind_of
from .context import emit_json

SHOWN_PER_KIND = 3   # notes printed of each kind; the rest are counted (all of them with --json)


def report_batch(batch, out, as_json: bool, quiet: bool = False) -> None:
    """The batch's notes and skipped gears on stderr (unless quiet), its summary line on stdout."""
    if as_json:
        emit_json({"programs": batch.programs, "lines": batch.lines, "path": out,
                   "program_ids": [batch.first_program_id, batch.last_program_id], "notes": list(batch.notes),
                   "note_kinds": note_counts(batch.notes), "skipped": list(batch.skipped),
                   "dry_run": batch.dry_run})
        return
    if not quiet:
        _show_notes(batch.notes)
        for reason in batch.skipped:
            click.echo(f"skipped: {reason}", err=True)
    click.echo(summary(batch, out))


def note_counts(notes) -> dict[str, int]:
    """Notes by kind, the commonest first (ties in NOTE_KINDS' order)."""
    counts = Counter(kind_of(note) for note in notes)
    order = list(NOTE_KINDS)
    return dict(sorted(counts.items(), key=lambda item: (-item[1], order.index(item[0]))))


def _show_notes(notes) -> None:
    for kind, count in note_counts(notes).items():
        more = f"; the first {SHOWN_PER_KIND} (all with --json)" if count > SHOWN_PER_KIND else ""
        click.echo(f"{count} note(s) of kind {kind!r}{more}:", err=True)
        for note in [note for note in notes if kind_of(note) == kind][:SHOWN_PER_KIND]:
            click.echo(f"note: {note}", err=True)


def summary(batch, out) -> str:
    """One line: programs stored (or, a dry run, that would be), skipped, notes by kind."""
    if batch.dry_run:
        stored = f"dry run: would store {batch.programs} program(s), {batch.lines} lines; nothing stored"
    else:
        stored = (f"stored {batch.programs} program(s) {batch.first_program_id}…{batch.last_program_id}, "
                  f"{batch.lines} lines" + (f", written to {out}" if out else ""))
    skipped = (f"skipped {len(batch.skipped)} bad of {len(batch.skipped) + batch.programs} (--skip-bad): their "
               "programs are not stored" if batch.skipped else "skipped none")
    counts = note_counts(batch.notes)
    noted = ", ".join(f"{count} {kind}" for kind, count in counts.items()) if counts else "none"
    return f"{stored}; {skipped}; notes: {noted}"
