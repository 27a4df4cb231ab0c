"""How every list and show command prints records (issue 16): columns declared as data, and three
forms of one list: an aligned table for a person (the count on stderr, so a pipe gets only rows),
one JSON line `{"<things>": [...]}` for a program, CSV (a header, then one line per record) for a
spreadsheet. Records are dicts with the common key names (gear_id, job_id, program_id, hob_id,
class), built by the library."""
from __future__ import annotations

import functools
import re
from collections.abc import Callable
from datetime import date, datetime
from decimal import Decimal
from typing import Any

import click
import msgspec

from ..json_text import cell, exact_json
from .context import emit_json


def csv_cell(value: Any) -> Any:
    """A value as a CSV cell holds it: empty for none, times in ISO 8601, numbers in full (a numeric
    column's value digit for digit as stored: 0.0000001, never 1E-7, which the importers refuse), text
    that a spreadsheet would run as a formula quoted (inert_text)."""
    if value is None:
        return ""
    if isinstance(value, Decimal):
        return format(value, "f")
    if isinstance(value, (list, tuple)):   # e.g. the classes a row is shared with: one cell, space-separated
        return inert_text(" ".join(str(item) for item in value))
    if isinstance(value, str):
        return inert_text(value)
    return value.isoformat() if isinstance(value, (datetime, date)) else value


# a cell beginning so is a formula to Excel and LibreOffice (the full-width forms too: Excel in
# CJK locales reads them as the ASCII ones)
FORMULA_START = ("=", "+", "@", "\t", "\r", "\uff1d", "\uff0b", "\uff20", "\uff0d")
# -5, -0.25, -.5, -1e-3: a negative number, not a formula
NUMBER_TEXT = re.compile(r"-(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def inert_text(text: str) -> str:
    """The text with a leading ' if a spreadsheet would take it for a formula (CSV injection,
    OWASP's advice): a material or hob id like `=cmd|'/c calc'!A1` must open as text, never run.
    A text starting with - is quoted unless the whole of it is a negative number."""
    formula = text.startswith(FORMULA_START) or (text.startswith("-") and not NUMBER_TEXT.fullmatch(text))
    return f"'{text}" if formula else text


class Column(msgspec.Struct, frozen=True):
    """One column of a list: its heading in the table, the record's key (also the CSV header),
    and how a table shows the value."""
    heading: str
    key: str
    format: Callable[[Any], str] = cell


DAY = click.DateTime(formats=["%Y-%m-%d"])   # --since/--until: a bad day is a one-line usage error


def day(value: datetime | None) -> date | None:
    """The day of a DAY option (click gives a datetime at midnight)."""
    return value.date() if value else None


def day_options(stored: str) -> Callable:
    """Adds --since and --until (whole days, both included) to a list command, e.g. stored='gears stored'."""
    def decorate(command: Callable) -> Callable:
        command = click.option("--until", type=DAY, metavar="YYYY-MM-DD",
                               help=f"Only {stored} on this day or earlier.")(command)
        return click.option("--since", type=DAY, metavar="YYYY-MM-DD",
                            help=f"Only {stored} on this day or later.")(command)
    return decorate


def list_options(things: str) -> Callable:
    """Adds --json and --csv to a list command; the command gets `output` ('json', 'csv' or None:
    the table). Both at once is a usage error."""
    def decorate(command: Callable) -> Callable:
        @functools.wraps(command)
        def with_output(*args, as_json: bool, as_csv: bool, **kwargs):
            chosen = one_of(click.get_current_context(), {"as_json": as_json, "as_csv": as_csv})
            output = {"as_json": "json", "as_csv": "csv"}.get(chosen) if chosen is not None else None
            return command(*args, output=output, **kwargs)
        with_output = click.option("--csv", "as_csv", is_flag=True,
                                   help="Print CSV: a header line of keys, then one line per record.")(with_output)
        return click.option("--json", "as_json", is_flag=True,
                            help=f"Print one JSON line: {{\"{things}\": [...]}}.")(with_output)
    return decorate


def one_of(ctx: click.Context, flags: dict[str, bool]) -> str | None:
    """The one flag on of a pair that exclude each other (--json/--csv, --draft/--released), by
    parameter name. A flag typed on the command line wins over one on by the environment or the
    config file; two typed, or two on by default, is a usage error naming both."""
    typed = [name for name, on in flags.items()
             if on and ctx.get_parameter_source(name) is click.core.ParameterSource.COMMANDLINE]
    chosen = typed or [name for name, on in flags.items() if on]
    if len(chosen) > 1:
        named = [f"--{name.removeprefix('as_').replace('_', '-')}" for name in chosen]
        raise click.UsageError(f"{' and '.join(named)}: give one of the two")
    return chosen[0] if chosen else None


def emit_list(output: str | None, things: str, columns: tuple[Column, ...], records: list[dict]) -> None:
    """The records in the form asked for; the table's count goes to stderr."""
    if output == "json":
        click.echo(exact_json({things: records}))
    elif output == "csv":
        click.echo(csv_text(columns, records), nl=False)
    else:
        click.echo(table_text(columns, records))
        click.echo(f"{len(records)} {things}", err=True)


def csv_text(columns: tuple[Column, ...], records: list[dict]) -> str:
    rows = [[column.key for column in columns]]
    rows += [[csv_cell(record.get(column.key)) for column in columns] for record in records]
    return "".join(csv_line(row) for row in rows)


def csv_line(cells: list) -> str:
    """One record, RFC 4180 quoting: a cell holding a comma, a quote, CR or LF in double quotes
    (Python's csv writer leaves a lone CR bare when lines end in LF, which splits the record)."""
    if cells == [""]:
        return '""\n'   # else a blank line, which readers skip
    return ",".join(_csv_field(str(cell)) for cell in cells) + "\n"


def _csv_field(text: str) -> str:
    quoted = any(special in text for special in ',"\r\n')
    return '"' + text.replace('"', '""') + '"' if quoted else text


def table_text(columns: tuple[Column, ...], records: list[dict]) -> str:
    """Headings and cells left-aligned, each column as wide as its widest cell."""
    rows = [[column.heading for column in columns]]
    rows += [[column.format(record.get(column.key)) for column in columns] for record in records]
    widths = [max(len(row[at]) for row in rows) for at in range(len(columns))]
    return "\n".join("  ".join(f"{text:{width}}" for text, width in zip(row, widths)).rstrip() for row in rows)


def fields_text(fields: tuple[Column, ...], record: dict) -> str:
    """One record as `label: value` lines (the show commands)."""
    width = max(len(field.heading) for field in fields) + 2
    return "\n".join(f"{field.heading + ':':{width}}{field.format(record.get(field.key))}" for field in fields)


def emit_record(as_json: bool, thing: str, fields: tuple[Column, ...], record: dict,
                sections: tuple[tuple[str, tuple[Column, ...], str], ...] = ()) -> None:
    """A show command's record: one JSON line {thing: record}, or its fields and then each
    (title, columns, key) section of related records."""
    if as_json:
        emit_json({thing: record})
        return
    click.echo(fields_text(fields, record))
    for title, columns, key in sections:
        click.echo(section_text(title, columns, record[key]))


def section_text(title: str, columns: tuple[Column, ...], records: list[dict]) -> str:
    """A show command's list of related records (a gear's jobs, a job's programs): a blank line,
    the title and count, the table if there is anything."""
    return f"\n{title}: {len(records)}" + (f"\n{table_text(columns, records)}" if records else "")
