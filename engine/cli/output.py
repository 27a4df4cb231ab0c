"""How every list and show command prints records (issue 16): columns declared as data, and three
forms of one list: an aligned table for a person (the count on stderr, so a pipe gets only rows),
one JSON line `{"<things>": [...]}` for a program, CSV (a header, then one line per record) for a
spreadsheet. Records are dicts with the common key names (gear_id, job_id, program_id, hob_id,
class), built by the library."""
from __future__ import annotations

import csv
import functools
import io
from dataclasses import dataclass
from datetime import date, datetime
from typing import Any, Callable

import click

from .context import emit_json


def cell(value: Any) -> str:
    """A value as a table shows it: '-' for none, 2.0 as 2, a time to the minute."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, datetime):
        return value.isoformat(sep=" ", timespec="minutes")
    return str(value)


def csv_cell(value: Any) -> Any:
    """A value as a CSV cell holds it: empty for none, times in ISO 8601, numbers in full."""
    if value is None:
        return ""
    if isinstance(value, (list, tuple)):   # e.g. the classes a row is shared with: one cell, space-separated
        return " ".join(str(item) for item in value)
    return value.isoformat() if isinstance(value, (datetime, date)) else value


@dataclass(frozen=True)
class Column:
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
            if as_json and as_csv:
                raise click.UsageError("--json and --csv: give one of the two")
            return command(*args, output="json" if as_json else "csv" if as_csv else None, **kwargs)
        with_output = click.option("--csv", "as_csv", is_flag=True,
                                   help="Print CSV: a header line of keys, then one line per record.")(with_output)
        return click.option("--json", "as_json", is_flag=True,
                            help=f"Print one JSON line: {{\"{things}\": [...]}}.")(with_output)
    return decorate


def emit_list(output: str | None, things: str, columns: tuple[Column, ...], records: list[dict]) -> None:
    """The records in the form asked for; the table's count goes to stderr."""
    if output == "json":
        emit_json({things: records})
    elif output == "csv":
        click.echo(csv_text(columns, records), nl=False)
    else:
        click.echo(table_text(columns, records))
        click.echo(f"{len(records)} {things}", err=True)


def csv_text(columns: tuple[Column, ...], records: list[dict]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(column.key for column in columns)
    writer.writerows([csv_cell(record.get(column.key)) for column in columns] for record in records)
    return buffer.getvalue()


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


def section_text(title: str, columns: tuple[Column, ...], records: list[dict]) -> str:
    """A show command's list of related records (a gear's jobs, a job's programs): a blank line,
    the title and count, the table if there is anything."""
    return f"\n{title}: {len(records)}" + (f"\n{table_text(columns, records)}" if records else "")
