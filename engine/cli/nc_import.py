"""`engine import-nc`: bring a proven NC program in as the standard code of a class."""
from __future__ import annotations

from dataclasses import asdict

import click

from .context import connection, emit_json, keyed


@click.command("import-nc")
@click.argument("nc_file", type=click.Path(dir_okay=False))
@click.option("--class", "gear_class", required=True, help="Class whose template the program becomes (created if new).")
@click.option("--params", "params_file", type=click.Path(dir_okay=False),
              help="The job's parameter values: JSON {name: value} or CSV name,value. "
                   "Numbers equal to a value become references to it.")
@click.option("--modules", "modules_file", type=click.Path(dir_okay=False),
              help="Corrections of the module assignment: CSV line_no,t (1-based program lines).")
@click.option("--parent", help="Parent class in the tree, for a new class.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object (rows, parameterised, modules, ...).")
@click.pass_context
def import_nc_command(ctx, nc_file, gear_class, params_file, modules_file, parent, as_json):
    """Import NC_FILE as the class's template: one row per line, all or nothing.

    Instantiating the class with the same parameter values gives NC_FILE back line for line.
    """
    from ..library.nc_import import import_nc, read_modules, read_params

    params = read_params(params_file) if params_file else None
    modules = read_modules(modules_file) if modules_file else None
    with connection(ctx) as conn:
        report = import_nc(conn, nc_file, gear_class, params, modules, parent)
    if as_json:
        emit_json(keyed(asdict(report)))
        return
    modules_text = ", ".join(f"{t} {count}" for t, count in report.modules.items())
    state = "created" if report.created else ("replaced" if report.changed else "unchanged (identical rows)")
    click.echo(f"class {report.gear_class}: {state}, {report.rows} rows ({modules_text}), "
               f"{report.parameterised} parameter reference(s), version {report.version}")
    if report.released_version != report.version:
        click.echo(_draft_note(report), err=True)
    for value, names in report.ambiguous.items():
        click.echo(f"  value {value} belongs to {', '.join(names)}: used {names[0]}", err=True)


def _draft_note(report) -> str:
    """Runners keep the released version: say what they get and how to try and release the import."""
    released = f"v{report.released_version}" if report.released_version is not None else "none"
    return (f"  version {report.version} is a draft (runners get the released version: {released}); an editor tries it "
            f"with `engine instantiate --draft`, `engine template release --class {report.gear_class}` releases it")
