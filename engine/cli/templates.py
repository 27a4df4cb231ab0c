"""`engine template list|export|import|history|diff|restore|shared` and `engine lint`: the
templates of the gear classes and their versions."""
from __future__ import annotations

import sys

import click

from ..errors import EngineError
from ..nc.layout import NcLayout
from .context import connection, emit_json, file_folder
from .ids import VERSION
from .output import Column, emit_list, list_options
from .refactor import template_shared
from .release import template_release

CLASS_COLUMNS = (Column("class", "class"), Column("parent", "parent"), Column("version", "template_version"),
                 Column("rows", "rows"), Column("released", "released"), Column("description", "description"))


@click.group()
def template():
    """Templates of gear classes: list, export and import as CSV (id,t,n,p_calc,s,o,p_emit, and
    line_ending,final_newline for a class not LF with a final newline); history, diff and restore
    of their versions."""


template.add_command(template_shared)   # which classes share each row: reported with the refactor
template.add_command(template_release)  # the gate between a draft and the shop floor


@template.command("list")
@list_options("classes")
@click.pass_context
def template_list(ctx, output):
    """Every gear class with its parent, template version and number of rows (its own and inherited),
    and its released version. At a plant, which receives released versions only, the version is the
    released one and the rows are its rows.

    Example: engine template list --json
    """
    from ..templates.store import class_records

    with connection(ctx) as conn:
        classes = class_records(conn)
    emit_list(output, "classes", CLASS_COLUMNS, classes)


@template.command("export")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--out", type=click.Path(dir_okay=False), help="Write to this file instead of stdout; its folder "
              "must exist unless --mkdir.")
@click.option("--mkdir", is_flag=True, help="Create the folder of --out (and those above it) if missing.")
@click.pass_context
def template_export(ctx, gear_class, out, mkdir):
    """Print the class's assembled template as CSV. A class whose programs are written other than
    LF with a final newline (imported from such a file) gives that on every row (line_ending
    lf|crlf, final_newline yes|no), so an import elsewhere writes the same bytes. At a plant, which
    receives the head office's released versions only, the class's released version."""
    from ..db.origin import this_plant
    from ..nc.layout import class_layout
    from ..templates.store import load_template
    from ..templates.template_csv import export_csv
    from ..templates.versions import released_template

    with connection(ctx) as conn:
        if this_plant(conn) > 0:
            template = released_template(conn, gear_class)
            text = export_csv(template, class_layout(conn, gear_class, template.version))
        else:
            text = export_csv(load_template(conn, gear_class), class_layout(conn, gear_class))
    if out:
        _write_export(out, text, mkdir)
    else:
        click.echo(text, nl=False)


def _write_export(out: str, text: str, mkdir: bool) -> None:
    """The exported CSV written to --out, into an existing folder (or one --mkdir makes)."""
    file_folder(out, mkdir)
    try:
        with open(out, "w", encoding="utf-8", newline="") as file:
            file.write(text)
    except OSError as error:
        raise EngineError(f"--out {out}: cannot be written ({error.strerror or error}); give a file you can "
                          "write") from None


@template.command("import")
@click.option("--class", "gear_class", required=True, help="Gear class name (created if new).")
@click.option("--parent", help="Parent class in the tree, for a new class.")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.pass_context
def template_import(ctx, gear_class, parent, csv_file):
    """Replace the class's rows with CSV_FILE; every expression is checked first (all or nothing).
    The line_ending and final_newline columns, if the CSV has them, set the class's layout (a change
    of it is a new draft version, as a change of rows is, until `engine template release`); a CSV
    without them leaves it as it is."""
    from ..nc.layout import class_layout, store_layout
    from ..templates.store import ensure_class, replace_template
    from ..templates.template_csv import read_template_csv

    read = read_template_csv(csv_file)
    with connection(ctx) as conn:
        with conn.transaction():
            created = ensure_class(conn, gear_class, parent)
            changed = replace_template(conn, gear_class, read.rows)
            relaid = read.layout is not None and store_layout(conn, gear_class, read.layout)
        version = conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (gear_class,)).fetchone()[0]
        layout = class_layout(conn, gear_class)
    state = "created" if created else ("replaced" if changed else
                                       "layout changed (identical rows)" if relaid else "unchanged (identical rows)")
    click.echo(f"class {gear_class}: {state}, {len(read.rows)} rows, version {version}, {layout.said}")


@template.command("history")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {versions: [...]}.")
@click.pass_context
def template_history(ctx, gear_class, as_json):
    """Every stored version of the class, oldest first: when, who, rows, its state (released, retired,
    draft, superseded), its release (who, when, how, programs changed of stored jobs) and which rows
    changed. A release is re-checked as it is shown (lint, analysis and its recorded golden tests
    against the released rows): "gate passed" only for one the engine's gate made that passes now.

    Example: engine template history --class spur
    """
    from ..release.recheck import verdict
    from ..release.shown import release_text, version_json
    from ..templates.history import history

    with connection(ctx) as conn:
        entries = history(conn, gear_class)
        verdicts = {entry.version: verdict(conn, gear_class, entry.release) for entry in entries if entry.release}
    if as_json:
        return emit_json({"class": gear_class,
                          "versions": [version_json(entry, verdicts.get(entry.version)) for entry in entries]})
    for number, entry in enumerate(entries):
        layout = _layout_text(entry.layout, entries[number - 1].layout if number else NcLayout())
        changes = _changes_text(entry.changes, first=number == 0, relaid=bool(layout))
        click.echo(f"v{entry.version:<4} {entry.state:10} {entry.created_at:%Y-%m-%d %H:%M:%S} by "
                   f"{entry.created_by:14} {entry.rows:3} rows  {changes}{layout}".rstrip())
        if entry.release is not None:
            click.echo(f"      {release_text(entry.release, verdicts[entry.version])}")


def _layout_text(layout, before) -> str:
    """The layout a version's programs are written with, where it differs from the version
    before (from LF with a final newline for the first)."""
    return "" if layout == before else f"  layout {layout.said}"


def _changes_text(changes, first: bool, relaid: bool = False) -> str:
    """Which rows a version changed: each row, or counts per operation when there are many."""
    if not changes:
        return "" if first or relaid else "(rows inherited from a parent class changed)"
    if len(changes) <= 6:
        return ", ".join(f"{operation} {row_id}" for row_id, operation in changes)
    operations = [operation for _, operation in changes]
    return ", ".join(f"{operation} x{operations.count(operation)}" for operation in dict.fromkeys(operations))


@template.command("diff")
@click.option("--class", "gear_class", required=True, help="Gear class name.")
@click.option("--from", "from_version", type=VERSION, required=True, help="Earlier version (see `template history`).")
@click.option("--to", "to_version", type=VERSION, required=True, help="Later version.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {changes: [{row_id, kind, old, new}]}.")
@click.pass_context
def template_diff(ctx, gear_class, from_version, to_version, as_json):
    """Rows added (+), removed (-) and changed (~) between two versions of the class, with old and new
    values, and the layout (line ending, final newline) if it changed."""
    from ..release.shown import diff_json
    from ..templates.history import diff, layout_change

    with connection(ctx) as conn:
        changes = diff(conn, gear_class, from_version, to_version)
        relaid = layout_change(conn, gear_class, from_version, to_version)
    if as_json:
        return emit_json(diff_json(gear_class, from_version, to_version, changes, relaid))
    if relaid:
        click.echo(f"~ layout: {relaid[0].said} -> {relaid[1].said}")
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
@click.option("--version", type=VERSION, required=True, help="The version to bring back (see `template history`).")
@click.pass_context
def template_restore(ctx, gear_class, version):
    """Make the class's template what it was in an earlier version, as a new version (history is kept)."""
    from ..templates.history import restore

    with connection(ctx) as conn:
        changed, current = restore(conn, gear_class, version)
    state = f"restored version {version} as version {current}" if changed else \
        f"unchanged: version {current} already has the rows of version {version}"
    click.echo(f"class {gear_class}: {state}")


@click.command()
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {errors: [...]}.")
@click.pass_context
def lint(ctx, as_json):
    """Check every expression of every template: parses, is allowed, names known parameters."""
    from ..programs import all_models  # noqa: F401  (registers every model)
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

