"""`engine import-nc`: bring a proven NC program in as the standard code of a class."""
from __future__ import annotations

import click

from .context import connection, emit_json, keyed, record_dict


@click.command("import-nc")
@click.argument("nc_file", type=click.Path(dir_okay=False))
@click.option("--class", "gear_class", required=True, help="Class whose template the program becomes (created if new).")
@click.option("--params", "params_file", type=click.Path(dir_okay=False),
              help="The job's parameters: JSON {name: value} or {name: {\"value\": v, \"addresses\": [\"F\"]}}, "
                   "or CSV name,value[,addresses]. A number equal to a value becomes a reference to it at the "
                   "addresses the parameter names (plain value: every address but G M N O T $, and never a number "
                   "that names a block, program, tool edge or spindle, nor a cycle's U W R); never a number "
                   "inside [...] or a spindle clamp (G50 S). Equal numbers left as written are listed with "
                   "their lines and the reason. A bound form's value must be a number; a bound word is "
                   "written with the value's own digits, never rounded.")
@click.option("--modules", "modules_file", type=click.Path(dir_okay=False),
              help="Corrections of the module assignment: CSV line_no,t (1-based program lines).")
@click.option("--parent", help="Parent class in the tree, for a new class.")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object (rows, parameterised, modules, bindings, left_alone, ...).")
@click.pass_context
def import_nc_command(ctx, nc_file, gear_class, params_file, modules_file, parent, as_json):
    """Import NC_FILE as the class's template: one row per line, all or nothing.

    Instantiating the class with the same parameter values gives NC_FILE back line for line.
    A tab in NC_FILE is refused, naming its line: replace tabs with spaces.
    """
    from ..library.nc_import import import_nc, read_modules, read_params

    params = read_params(params_file) if params_file else None
    modules = read_modules(modules_file) if modules_file else None
    with connection(ctx) as conn:
        report = import_nc(conn, nc_file, gear_class, params, modules, parent)
    if as_json:
        emit_json(keyed(record_dict(report)))
        return
    modules_text = ", ".join(f"{t} {count}" for t, count in report.modules.items())
    state = "created" if report.created else ("replaced" if report.changed else "unchanged (identical rows)")
    click.echo(f"class {report.gear_class}: {state}, {report.rows} rows ({modules_text}), "
               f"{report.parameterised} parameter reference(s), version {report.version}")
    if report.released_version != report.version:
        click.echo(_draft_note(report), err=True)
    for binding in report.bindings:
        click.echo(_binding_line(binding))
    for value, names in report.ambiguous.items():
        click.echo(f"  value {value} belongs to {', '.join(names)}: used {names[0]}", err=True)
    for left in report.left_alone:
        click.echo(f"  line {left['line']}: {left['word']} equals {left['parameter']}, but {left['why']}: "
                   "left as written", err=True)


def _binding_line(binding: dict) -> str:
    """`  feed → F: 3 word(s) (F 3: lines 4, 9-10); left alone: U 1 (line 7)`: a parameter, the
    addresses it binds, the words it bound and the equal words it left as written, per address."""
    lines = binding.get("lines", {})
    at = "; ".join(f"{address} {count}: {_lines(lines.get(address, []))}" for address, count in binding["at"].items())
    left = "; ".join(f"{address} {entry['words']} ({_lines(entry['lines'])})"
                     for address, entry in binding.get("left_alone", {}).items())
    return (f"  {binding['parameter']} → {binding['binds']}: {binding['words']} word(s)" + (f" ({at})" if at else "")
            + (f"; left alone: {left}" if left else ""))


SHOWN_RANGES = 8   # line ranges printed per address; the rest counted (--json lists every line)


def _lines(numbers: list[int]) -> str:
    """`lines 4, 9-10` (`line 7`): line numbers as ranges, the first SHOWN_RANGES of them."""
    ranges: list[list[int]] = []
    for number in numbers:
        if ranges and number <= ranges[-1][1] + 1:
            ranges[-1][1] = max(ranges[-1][1], number)
        else:
            ranges.append([number, number])
    shown = [f"{low}" if low == high else f"{low}-{high}" for low, high in ranges[:SHOWN_RANGES]]
    more = f" … and {len(ranges) - SHOWN_RANGES} more range(s)" if len(ranges) > SHOWN_RANGES else ""
    return ("line " if len(numbers) == 1 else "lines ") + ", ".join(shown) + more


def _draft_note(report) -> str:
    """Runners keep the released version: say what they get and how to try and release the import."""
    released = f"v{report.released_version}" if report.released_version is not None else "none"
    return (f"  version {report.version} is a draft (runners get the released version: {released}); an editor tries it "
            f"with `engine instantiate --draft`, `engine template release --class {report.gear_class}` releases it")
