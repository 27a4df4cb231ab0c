"""Commands for gears, instantiation, templates and lint (registered on engine.cli.main)."""
from __future__ import annotations

import re
import sys

import click

from .app import connection, emit_json, main
from ..errors import EngineError

RANGE = re.compile(r"^\s*(\d+)\s*(?:-\s*(\d+))?\s*$")


@main.group()
def gears():
    """Workpieces: import them from CSV (columns of design notes §9)."""


@gears.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {imported: N}.")
@click.pass_context
def gears_import(ctx, csv_file, as_json):
    """Import gears from CSV_FILE; any bad row stops the whole file (nothing stored)."""
    from ..gears.gear_import import import_gears

    with connection(ctx) as conn:
        count = import_gears(conn, csv_file)
    emit_json({"imported": count}) if as_json else click.echo(f"imported {count} gear(s) from {csv_file}")


@gears.command("units")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.pass_context
def gears_units(ctx, csv_file):
    """Import further toothed units of multi-unit (duplex) gears from CSV_FILE.

    Columns: gear_id, unit (2, 3, ...), teeth, face_width, tip_diameter, root_diameter,
    z_top (Z of the unit's upper face; the gear's top face is Z = 0). The units of each
    gear in the file replace its units; any bad row stops the whole file."""
    from ..gears.units import import_units

    with connection(ctx) as conn:
        count = import_units(conn, csv_file)
    click.echo(f"imported {count} unit(s) from {csv_file}")


@main.command()
@click.option("--gear", "gear_id", type=int, required=True, help="Gear id.")
@click.pass_context
def classify(ctx, gear_id):
    """Explain a gear's class: the group-technology decision path (face-width variation,
    generating line, units), the class stored, its hobbing model and the hob it gets."""
    from ..gears.classify import explain_gear

    with connection(ctx) as conn:
        report = explain_gear(conn, gear_id)
    click.echo("\n".join(report.lines()))


def parse_range(text: str) -> tuple[int, int]:
    match = RANGE.match(text)
    if not match:
        raise EngineError(f"--gears {text!r} is not a range like 1-5000 or 42")
    first = int(match.group(1))
    last = int(match.group(2) or first)
    if last < first:
        raise EngineError(f"--gears {text!r}: the range ends before it starts")
    return first, last


@main.command()
@click.option("--gear", "gear_id", type=int, help="Gear id: compute a new job and its program.")
@click.option("--job", "job_id", type=int, help="Stored job id: instantiate again with its (edited) parameters.")
@click.option("--gears", "gear_range", help="Batch: gear ids FIRST-LAST (all stored, or none).")
@click.option("--all", "all_gears", is_flag=True, help="Batch: every gear.")
@click.option("--out", type=click.Path(), help="Write the .MPF file here (a directory for batches).")
@click.option("--machine", help="Machine record (default hobber-840d).")
@click.option("--cuts", type=click.IntRange(1, 2), help="1 = single cut, 2 = rough then finish (default by module).")
@click.option("--coolant/--no-coolant", default=True, show_default=True, help="Coolant M8/M9.")
@click.option("--shift-y", type=float, default=0.0, help="Hob shift position Y for this part, mm.")
@click.option("--shift-per-part", type=float, default=0.0,
              help="Shift the hob by this many mm every part (R11 counts), wrapping within the hob's usable length.")
@click.option("--feed-mode", type=click.Choice(["climb", "conventional", "conventional-climb"]), default="climb",
              show_default=True, help="Axial pass direction; conventional-climb: rough conventional, finish climb.")
@click.option("--tailstock/--no-tailstock", default=True, show_default=True, help="Tailstock clamp M20/M21.")
@click.option("--worm-feed", type=click.Choice(["radial", "tangential"]), default="radial", show_default=True,
              help="Worm wheels: radial plunge, or tangential feed along Y.")
@click.option("--hob-speed", type=int, help="Override the hob speed n0, r/min.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object (program_id, path, lines, ...).")
@click.pass_context
def instantiate(ctx, gear_id, job_id, gear_range, all_gears, out, machine, cuts, coolant, shift_y,
                shift_per_part, feed_mode, tailstock, worm_feed, hob_speed, as_json):
    """Produce the NC program of a gear (or a stored job, or a batch of gears).

    The program is checked against the machine's limits, stored with the template
    version it came from, printed (single program) and written to --out.
    """
    from ..hobbing.choices import Choices
    from ..programs.instantiate import instantiate_gear, instantiate_gears, instantiate_job

    chosen = [name for name, value in (("--gear", gear_id), ("--job", job_id), ("--gears", gear_range),
                                       ("--all", all_gears)) if value]
    if len(chosen) != 1:
        raise EngineError("give exactly one of --gear ID, --job ID, --gears FIRST-LAST, --all")
    choices = Choices(cuts=cuts, coolant=coolant, shift_y=shift_y, shift_per_part=shift_per_part,
                      feed_mode=feed_mode, tailstock=tailstock, worm_feed=worm_feed)
    overrides = {"hob_speed": hob_speed}
    with connection(ctx) as conn:
        if gear_id is not None:
            program = instantiate_gear(conn, gear_id, machine=machine, choices=choices, overrides=overrides, out=out)
        elif job_id is not None:
            program = instantiate_job(conn, job_id, out=out)
        else:
            first, last = parse_range(gear_range) if gear_range else (None, None)
            programs = instantiate_gears(conn, first, last, machine=machine, choices=choices,
                                         overrides=overrides, out=out)
            return _report_batch(programs, out, as_json)
    _report_program(program, as_json)


def _report_program(program, as_json: bool) -> None:
    if as_json:
        emit_json({"program_id": program.program_id, "job_id": program.job_id, "name": program.name,
                   "path": program.path, "lines": len(program.lines), "gear_class": program.gear_class,
                   "template_version": program.template_version, "template_hash": program.template_hash})
        return
    if program.path is None:
        click.echo(program.text, nl=False)
    click.echo(f"program {program.program_id} (job {program.job_id}, {len(program.lines)} lines) "
               f"from {program.gear_class} v{program.template_version}"
               + (f" written to {program.path}" if program.path else ""), err=True)


def _report_batch(batch, out, as_json: bool) -> None:
    if as_json:
        emit_json({"programs": batch.programs, "lines": batch.lines, "path": out,
                   "program_ids": [batch.first_program_id, batch.last_program_id]})
    else:
        click.echo(f"stored {batch.programs} program(s) {batch.first_program_id}…{batch.last_program_id}, "
                   f"{batch.lines} lines" + (f", written to {out}" if out else ""))


@main.group()
def template():
    """Templates of gear classes: list, export and import as CSV (id,t,n,p_calc,s,o,p_emit);
    history, diff and restore of their versions."""


@template.command("list")
@click.pass_context
def template_list(ctx):
    """Every gear class with its parent, template version and number of rows."""
    from ..templates.store import list_classes

    with connection(ctx) as conn:
        for name, parent, version, rows, description in list_classes(conn):
            click.echo(f"{name:14} parent={parent or '-':12} v{version:<3} {rows:3} rows  {description}")


@template.command("export")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--out", type=click.Path(dir_okay=False), help="Write to this file instead of stdout.")
@click.pass_context
def template_export(ctx, gear_class, out):
    """Print the class's assembled template as CSV."""
    from ..templates.rows import export_csv
    from ..templates.store import load_template

    with connection(ctx) as conn:
        text = export_csv(load_template(conn, gear_class))
    if out:
        with open(out, "w", encoding="utf-8", newline="") as file:
            file.write(text)
    else:
        click.echo(text, nl=False)


@template.command("import")
@click.option("--class", "gear_class", required=True, help="Gear class name (created if new).")
@click.option("--parent", help="Parent class in the tree, for a new class.")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.pass_context
def template_import(ctx, gear_class, parent, csv_file):
    """Replace the class's rows with CSV_FILE; every expression is checked first (all or nothing)."""
    from ..templates.rows import read_csv
    from ..templates.store import ensure_class, replace_template

    rows = read_csv(csv_file)
    with connection(ctx) as conn:
        with conn.transaction():
            created = ensure_class(conn, gear_class, parent)
            changed = replace_template(conn, gear_class, rows)
        version = conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (gear_class,)).fetchone()[0]
    state = "created" if created else ("replaced" if changed else "unchanged (identical rows)")
    click.echo(f"class {gear_class}: {state}, {len(rows)} rows, version {version}")


@template.command("history")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {versions: [...]}.")
@click.pass_context
def template_history(ctx, gear_class, as_json):
    """Every stored version of the class, oldest first: when, who, rows, which rows changed."""
    from ..templates.history import history

    with connection(ctx) as conn:
        entries = history(conn, gear_class)
    if as_json:
        return emit_json({"gear_class": gear_class, "versions": [_version_json(entry) for entry in entries]})
    for number, entry in enumerate(entries):
        click.echo(f"v{entry.version:<4} {entry.created_at:%Y-%m-%d %H:%M:%S} by {entry.created_by:14} "
                   f"{entry.rows:3} rows  {_changes_text(entry.changes, first=number == 0)}".rstrip())


def _changes_text(changes, first: bool) -> str:
    """Which rows a version changed: each row, or counts per operation when there are many."""
    if not changes:
        return "" if first else "(rows inherited from a parent class changed)"
    if len(changes) <= 6:
        return ", ".join(f"{operation} {row_id}" for row_id, operation in changes)
    operations = [operation for _, operation in changes]
    return ", ".join(f"{operation} x{operations.count(operation)}" for operation in dict.fromkeys(operations))


def _version_json(entry) -> dict:
    return {"version": entry.version, "created_at": entry.created_at.isoformat(), "created_by": entry.created_by,
            "rows": entry.rows, "changes": [{"row_id": row_id, "operation": operation}
                                            for row_id, operation in entry.changes]}


@template.command("diff")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--from", "from_version", type=int, required=True, help="Earlier version (see `template history`).")
@click.option("--to", "to_version", type=int, required=True, help="Later version.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {changes: [{row_id, kind, old, new}]}.")
@click.pass_context
def template_diff(ctx, gear_class, from_version, to_version, as_json):
    """Rows added (+), removed (-) and changed (~) between two versions of the class, with old and new values."""
    from ..templates.history import diff

    with connection(ctx) as conn:
        changes = diff(conn, gear_class, from_version, to_version)
    if as_json:
        return emit_json({"gear_class": gear_class, "from": from_version, "to": to_version,
                          "changes": [{"row_id": c.row_id, "kind": c.kind, "old": c.old, "new": c.new}
                                      for c in changes]})
    for change in changes:
        click.echo("\n".join(_diff_lines(change)))
    click.echo(f"{len(changes)} row(s) differ between v{from_version} and v{to_version}", err=True)


def _diff_lines(change) -> list[str]:
    if change.kind == "added":
        return [f"+ {change.row_id}: {change.new}"]
    if change.kind == "removed":
        return [f"- {change.row_id}: {change.old}"]
    return [f"~ {change.row_id} {column}: {change.old[column]!r} -> {change.new[column]!r}"
            for column in change.columns]


@template.command("restore")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--version", type=int, required=True, help="The version to bring back (see `template history`).")
@click.pass_context
def template_restore(ctx, gear_class, version):
    """Make the class's template what it was in an earlier version, as a new version (history is kept)."""
    from ..templates.history import restore

    with connection(ctx) as conn:
        changed, current = restore(conn, gear_class, version)
    state = f"restored version {version} as version {current}" if changed else \
        f"unchanged: version {current} already has the rows of version {version}"
    click.echo(f"class {gear_class}: {state}")


@main.command()
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {errors: [...]}.")
@click.pass_context
def lint(ctx, as_json):
    """Check every expression of every template: parses, is allowed, names known parameters."""
    from ..templates.lint import lint_all

    with connection(ctx) as conn:
        problems = lint_all(conn)
    if as_json:
        emit_json({"errors": [str(problem) for problem in problems]})
    else:
        for problem in problems:
            click.echo(str(problem))
        click.echo(f"{len(problems)} problem(s)", err=True)
    if problems:
        sys.exit(1)
