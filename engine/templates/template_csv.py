"""The CSV form of a template (engine.templates.rows) that engineers export, edit and import.

The CSV of a class whose programs are not written LF with a final newline (an imported CRLF
file, or one without a final newline: issue 17) carries that layout in two more columns after the
rows' own, `line_ending` (lf or crlf) and `final_newline` (yes or no), on every row, so that the
class exported and imported into a fresh database writes the same bytes. Columns, not a comment
line: the one CSV reader and any spreadsheet read them as they read the rest. A blank cell takes
the value the other rows give; rows that disagree are refused. The CSV of any other class is as it
always was (seven columns: scripts and hand-added rows keep working), and a CSV without the two
columns leaves the class's stored layout as it is; to make a class LF again, give them (lf, yes)."""
from __future__ import annotations

import csv
import io
import re
from pathlib import Path

import msgspec

from ..csv_reader import (
    CellError,
    Column,
    CsvFile,
    CsvKind,
    declare,
    parse_text,
    parse_whole,
    read_csv_file,
    read_csv_text,
    refuse,
)
from ..errors import EngineError
from ..names import shown
from ..nc.layout import ENDING_NAMES, NcLayout
from ..nc.lineage import ENGINES_LINE
from .rows import CSV_COLUMNS, EXPRESSION_COLUMNS, MODULE_ORDER, Template, TemplateRow, writes_lineage

LAYOUT_COLUMNS = ("line_ending", "final_newline")   # optional: the class's layout, the same on every row
LINE_ENDINGS = {name: ending for ending, name in ENDING_NAMES.items()}
FINAL_NEWLINE = {"yes": True, "no": False}


def parse_line_ending(cell: str) -> str:
    if cell.strip().lower() not in LINE_ENDINGS:
        raise CellError("is not a line ending")
    return LINE_ENDINGS[cell.strip().lower()]


def parse_final_newline(cell: str) -> bool:
    if cell.strip().lower() not in FINAL_NEWLINE:
        raise CellError("is not yes or no")
    return FINAL_NEWLINE[cell.strip().lower()]


declare(parse_line_ending, "line ending", "write lf or crlf")
declare(parse_final_newline, "yes or no", "write yes (the last line ends with the line ending) or no")

# An expression cell may hold line breaks, and is kept as written (not stripped): the rows' hash is
# what a program records. The header must name every column of CSV_COLUMNS (checked in _template_file).
TEMPLATE_KIND = CsvKind("template", (
    Column("id", parse_whole, required=True), Column("t", parse_text), Column("n", parse_whole),
    *(Column(name, parse_text) for name in EXPRESSION_COLUMNS),
    Column("line_ending", parse_line_ending), Column("final_newline", parse_final_newline)),
    multiline=True, strip=False)


class TemplateCsv(msgspec.Struct, frozen=True):
    """A template CSV read: its rows, and the class's layout if the file gives one."""
    rows: list[TemplateRow]
    layout: NcLayout | None


def export_csv(template: Template, layout: NcLayout = NcLayout()) -> str:
    """The assembled template as CSV: id,t,n,p_calc,s,o,p_emit (absent = empty cell), and the
    class's line_ending,final_newline on every row unless `layout` is LF with a final newline."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    given = layout_cells(layout) if layout != NcLayout() else []
    writer.writerow(CSV_COLUMNS + LAYOUT_COLUMNS if given else CSV_COLUMNS)
    for row in template.rows:
        writer.writerow(["" if value is None else value for value in row.values()] + given)
    return buffer.getvalue()


def layout_cells(layout: NcLayout) -> list[str]:
    """The layout as the CSV writes it: ["crlf", "no"]."""
    return [ENDING_NAMES[layout.line_ending], "yes" if layout.final_newline else "no"]


MAX_CSV_BYTES = 32 << 20   # a template of 100,000 NC lines exports to about 10 MB
# A line inside a cell that starts like a template row: the cell swallowed the rows after it
# (a quote left open). An `s` cell may hold line breaks, but never a line like this.
ROW_START = re.compile(r"\n\s*\d+\s*,\s*(" + "|".join(MODULE_ORDER) + r")\s*,")


def read_csv(path: Path | str) -> list[TemplateRow]:
    """Template rows from a CSV file; every problem names the line."""
    return read_template_csv(path).rows


def read_template_csv(path: Path | str) -> TemplateCsv:
    """Template rows and the class's layout (None if not given) from a CSV file; every problem
    names the line."""
    path = Path(path)
    try:
        if path.stat().st_size > MAX_CSV_BYTES:
            raise EngineError(f"{path}: {path.stat().st_size} bytes, more than a template CSV may hold "
                              f"({MAX_CSV_BYTES} bytes); is it a template?")
    except OSError as error:
        raise EngineError(f"cannot read {path}: {error.strerror}") from None
    file = _template_file(read_csv_file(path, TEMPLATE_KIND))
    return TemplateCsv(_rows(file), _layout(file))


def parse_csv(text: str, source: str = "template CSV") -> list[TemplateRow]:
    """Rows of a template CSV, read strictly: a quote left open is refused at the line where it
    opens, not read on to the end of the file (which would lose every row after it)."""
    return _rows(_template_file(read_csv_text(text, source, TEMPLATE_KIND)))


def _template_file(file: CsvFile) -> CsvFile:
    """The file, if its header names every row column, and both layout columns or neither."""
    missing = [name for name in CSV_COLUMNS if name not in file.header]
    if missing:
        raise refuse(file.source, f"missing column(s) {', '.join(missing)}",
                     f"add them to the header ({','.join(CSV_COLUMNS)})")
    layout = [name for name in LAYOUT_COLUMNS if name in file.header]
    if len(layout) == 1:
        raise refuse(file.source, f"the header names {layout[0]} alone", f"give both {' and '.join(LAYOUT_COLUMNS)}, "
                     "or neither (the class's layout is then left as it is)")
    return file


def _layout(file: CsvFile) -> NcLayout | None:
    """The layout the rows give (a blank cell takes the others' value); None if no row gives one."""
    if LAYOUT_COLUMNS[0] not in file.header:
        return None
    values = [_one_value(file, column) for column in LAYOUT_COLUMNS]
    if values == [None, None]:
        return None
    if None in values:
        column = LAYOUT_COLUMNS[values.index(None)]
        raise refuse(file.source, f"no row gives {column}, but rows give the other layout column",
                     "give both on the rows, or neither (the class's layout is then left as it is)", column=column)
    return NcLayout(*values)


def _one_value(file: CsvFile, column: str):
    """The one value the rows give in the column, None if none does; rows that differ are refused."""
    given = [(line, record[column].strip(), _layout_value(file, column, line, record))
             for line, record in file.rows() if record[column].strip()]
    other = next(((line, cell) for line, cell, value in given if value != given[0][2]), None)
    if other is not None:
        raise refuse(file.source, f"{other[1]!r} differs from {given[0][1]!r} on line {given[0][0]}",
                     "a class has one layout: give the same value on every row, or leave the cell blank",
                     other[0], column)
    return given[0][2] if given else None


def _layout_value(file: CsvFile, column: str, line: int, record: dict):
    """The value of a layout cell; EngineError naming the line if it cannot be read."""
    value, problem = file.cell(TEMPLATE_KIND.column(column), record[column].strip(), line)
    if problem:
        raise EngineError(problem.said(file.source))
    return value


def _rows(file: CsvFile) -> list[TemplateRow]:
    rows, seen = [], set()
    for line, record in file.rows():
        row = _row_from_record(file, record, line)
        if row.id in seen:
            raise refuse(file.source, f"row id {row.id} appears twice", "give each row its own id", line, "id")
        seen.add(row.id)
        rows.append(row)
    if not rows:
        raise refuse(file.source, "has no template rows", f"give rows under the header {','.join(CSV_COLUMNS)}")
    return sorted(rows, key=lambda row: row.id)


def _whole(file: CsvFile, column: str, text: str, line: int) -> int:
    value, problem = file.cell(TEMPLATE_KIND.column(column), text.strip(), line)
    if problem:
        raise EngineError(problem.said(file.source))
    return value


def _row_from_record(file: CsvFile, record: dict, line: int) -> TemplateRow:
    row_id, n = _whole(file, "id", record["id"], line), _whole(file, "n", record["n"], line)
    n = 1 if n is None else n
    texts = {column: (record[column] if record[column] and record[column].strip() else None)
             for column in EXPRESSION_COLUMNS}
    swallowed = next((ROW_START.search(text) for text in texts.values() if text and ROW_START.search(text)), None)
    if swallowed:
        raise refuse(file.source, f"a cell runs on into what looks like a row ({swallowed.group().strip()!r}…): "
                                  "a quote opened on this line is not closed", "close the quote", line)
    if texts["o"] is not None and writes_lineage(texts["o"]):
        raise refuse(file.source, f"row {row_id} writes a lineage line {shown(texts['o'].strip())}",
                     f"remove the row ({ENGINES_LINE})", line, "o")
    return TemplateRow(row_id, (record["t"] or "").strip(), n, texts["p_calc"], texts["s"],
                       texts["o"], texts["p_emit"])
