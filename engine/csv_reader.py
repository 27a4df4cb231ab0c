"""One reader for every CSV file the engine reads (gears, gear units, hobs, cutting cases, templates,
job parameters, module types, the seed tables), with one phrasing of errors:

    <file>, line N, column <name>: <what is wrong>; <what to do>

A shop's files come from Excel as often as from a script, so the reader takes what Excel writes:
a byte-order mark, CRLF line ends, blank lines (also at the end), and the German Excel form — `;`
between the columns and a decimal comma (`2,5`) in number cells. The separator is the header's:
a header holding `;` and no `,` makes a `;` file. A `,` file whose row has more cells than the header,
next to a digit-comma-digit, is said to look like a decimal comma that split a value.

A malformed record (a cell count other than the header's, a quote left open) is refused naming the
line; the importers check every row before they store any, in one transaction.
"""
from __future__ import annotations

import csv
import io
import re
from collections.abc import Callable
from decimal import Decimal
from pathlib import Path
from typing import Any

import msgspec

from .errors import EngineError
from .names import shown
from .quantities import MAX_MAGNITUDE  # the records read from the database refuse the same

SEPARATORS = (",", ";")
DECIMAL_COMMA = re.compile(r"[+-]?(\d+,\d*|,\d+)([eE][+-]?\d{1,3})?")
SPLIT_DECIMAL = re.compile(r"\d,\d")
MAX_BYTES = 32 << 20   # a template of 100,000 NC lines exports to about 10 MB; no gear list comes near


class CellError(ValueError):
    """A cell that cannot be read; the message is what is wrong with it ("is not a number")."""


class Problem(msgspec.Struct, frozen=True):
    """One thing wrong with a file: where (line and column when known), what, and what to do."""

    line: int | None
    column: str | None
    what: str
    todo: str = ""

    def said(self, source: Any) -> str:
        place = [str(source)] + [f"line {self.line}"] * (self.line is not None)
        place += [f"column {self.column}"] * (self.column is not None)
        return f"{', '.join(place)}: {self.what}" + (f"; {self.todo}" if self.todo else "")


class CsvError(EngineError):
    """A CSV file refused for its rows: the message counts the bad rows, and `problems` holds one line
    per problem, in file order, each phrased as Problem.said."""

    def __init__(self, source: Any, problems: list[Problem], nothing: str = "nothing imported") -> None:
        problems = sorted(problems, key=lambda problem: problem.line or 0)   # stable: per line, column order
        self.problems = [problem.said(source) for problem in problems]
        self.bad_rows = len({problem.line for problem in problems})
        super().__init__(f"{source}: {self.bad_rows} bad row(s); {nothing}")


class CsvFileError(EngineError):
    """A CSV file refused as a whole (unreadable, no header, a malformed record): one line."""

    problems: list[str] = []


def refuse(source: Any, what: str, todo: str = "", line: int | None = None, column: str | None = None) -> EngineError:
    """One problem as an error to raise."""
    return CsvFileError(Problem(line, column, what, todo).said(source))


# --- the column declarations --------------------------------------------------------------

class Column(msgspec.Struct, frozen=True):
    """One declared column of a CSV kind: its name, how to read a cell (`parse`, whose kind — number,
    whole number, text… — the reader reads from TYPES), whether every row must give it, its unit, and
    what a given value must satisfy (`check`, said as `rule` after the value)."""

    name: str
    parse: Callable[[str], Any]
    required: bool = False
    check: Callable[[Any], bool] | None = None
    rule: str = ""
    db_name: str | None = None
    unit: str = ""
    header_optional: bool = False   # the header may leave it out, even where the kind wants every column
    hint: str = ""                  # what to do, where the column's bounds say more than its type's advice

    @property
    def column(self) -> str:
        return self.db_name or self.name

    @property
    def type(self) -> str:
        return TYPES.get(self.parse, ("text", ""))[0]

    @property
    def todo(self) -> str:
        if self.hint:
            return self.hint
        unit = f" in {self.unit}" if self.unit else ""
        return TYPES.get(self.parse, ("text", f"correct the {self.name}{unit}"))[1].format(unit=unit, name=self.name)


class CsvKind(msgspec.Struct, frozen=True):
    """What a kind of CSV file holds: its columns, whether a cell may span lines (template
    expressions may; elsewhere a record over several lines is a quote left open) and is kept as written."""

    name: str
    columns: tuple[Column, ...]
    multiline: bool = False
    strip: bool = True           # cells stripped of surrounding blanks (templates keep them as written)
    every_column: bool = False   # the header must name every column (not only the required ones)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(column.name for column in self.columns)

    def column(self, name: str) -> Column:
        return next(column for column in self.columns if column.name == name)


# --- cell parsers: text → value, or CellError ---------------------------------------------

NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d{1,3})?")


def parse_text(cell: str) -> str:
    return cell


def parse_number(cell: str) -> Decimal:
    if not NUMBER.fullmatch(cell):
        raise CellError("is not a number")
    value = Decimal(cell)
    if abs(value) > MAX_MAGNITUDE:
        raise CellError(f"is larger than {MAX_MAGNITUDE:g} in size (no quantity of a gear or hob is that large)")
    return value


INTEGER_MAX = 2_147_483_647  # PostgreSQL integer


def parse_whole(cell: str) -> int:
    if not NUMBER.fullmatch(cell):
        raise CellError("is not a whole number")
    value = Decimal(cell)
    if value != value.to_integral_value() or abs(value) > INTEGER_MAX:
        raise CellError("is not a whole number")
    return int(value)


def parse_positive_whole(cell: str) -> int:
    try:
        value = parse_whole(cell)
    except CellError:
        value = 0
    if value <= 0:
        raise CellError("is not a positive whole number")
    return value


def parse_number_or_text(cell: str):
    """A job parameter's value: a whole number as int, another number as float, else the text."""
    if re.fullmatch(r"[+-]?\d+", cell):
        return int(cell)
    return float(cell) if NUMBER.fullmatch(cell) else cell


# parser → (type, what to do with a bad cell); {unit} and {name} are filled in per column.
TYPES: dict[Callable, tuple[str, str]] = {
    parse_text: ("text", "correct the {name}"),
    parse_number: ("number", "write a number{unit} like 2.5"),
    parse_whole: ("whole number", "write a whole number like 7"),
    parse_positive_whole: ("positive whole number", "write a whole number from 1 up"),
    parse_number_or_text: ("number or text", "write a number like 2.5, or text"),
}


def number_types() -> frozenset:
    return frozenset(parse for parse, (kind, _) in TYPES.items() if "number" in kind)


def declare(parse: Callable, kind: str, todo: str) -> Callable:
    """Register a parser of a CSV kind's own (hand, class name…) with its type and what to do."""
    TYPES[parse] = (kind, todo)
    return parse


# --- reading the file ---------------------------------------------------------------------

class CsvFile(msgspec.Struct):
    """A file read: its separator, the header's column names (lower case) and every non-blank record
    after it with the line it starts on, its cells stripped and as many as the header's."""

    source: str
    separator: str
    header: list[str]
    records: list[tuple[int, list[str]]]

    def cell(self, column: Column, text: str, line: int | None) -> tuple[Any, Problem | None]:
        """(value, problem) of one cell; value None when the cell is empty (not given)."""
        return read_cell(column, text, line, self.separator)

    def rows(self) -> list[tuple[int, dict[str, str]]]:
        """Every record as {column name: cell}."""
        return [(line, dict(zip(self.header, cells))) for line, cells in self.records]


def read_cell(column: Column, text: str, line: int | None, separator: str = ",") -> tuple[Any, Problem | None]:
    """(value, problem) of one cell of a file with this separator; value None when the cell is empty."""
    if not text:
        return None, (Problem(line, column.name, "is missing", column.todo) if column.required else None)
    text, problem = _decimal_point(column, text, line, separator)
    if problem:
        return None, problem
    try:
        value = column.parse(text)
    except CellError as error:
        return None, Problem(line, column.name, f"{shown(text)} {error}", column.todo)
    if column.check is not None and not column.check(value):
        return value, Problem(line, column.name, f"{text} {column.rule}", column.todo)
    return value, None


def _decimal_point(column: Column, text: str, line: int | None, separator: str) -> tuple[str, Problem | None]:
    """A decimal comma is read as a point in a `;` file (German Excel); in a `,` file it is refused,
    as the cell was quoted on purpose or the value would have split."""
    if column.parse not in number_types() or not DECIMAL_COMMA.fullmatch(text):
        return text, None
    if separator == ";":
        return text.replace(",", "."), None
    return text, Problem(line, column.name, f"{shown(text)} has a decimal comma, but this file separates its "
                                            "columns with ','", f"write {text.replace(',', '.')}, or save the "
                                            "file with ';' between the columns")


def read_csv_file(path: str | Path, kind: CsvKind) -> CsvFile:
    """The file at `path` read as `kind`; refuses (CsvError) an unreadable or malformed file."""
    return read_csv_text(_text_of(Path(path)), str(path), kind)


def _text_of(path: Path) -> str:
    try:
        if path.stat().st_size > MAX_BYTES:
            raise refuse(path, f"{path.stat().st_size} bytes, more than a CSV file the engine reads may hold "
                               f"({MAX_BYTES} bytes)", "is it the right file?")
        data = path.read_bytes()
    except FileNotFoundError:
        raise refuse(path, "no such file", "give the path of an existing CSV file") from None
    except OSError as error:
        raise refuse(path, f"cannot read it ({error.strerror or error})",
                     "check the path and its permissions") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        raise refuse(path, f"not UTF-8 text (byte 0x{data[error.start]:02x} at offset {error.start})",
                     "save the file as UTF-8 (Excel: CSV UTF-8)", line=line) from None


def read_csv_text(text: str, source: str, kind: CsvKind) -> CsvFile:
    """`text` read as `kind`: separator, header and records, each record checked for its cell count."""
    if "\x00" in text:
        raise refuse(source, "holds a NUL character", "save the file as text",
                     line=text.count("\n", 0, text.index("\0")) + 1)
    separator = _separator(text, source)
    records = _records(text, source, separator, kind)
    if not records:
        raise refuse(source, "is empty", f"give a header line ({','.join(kind.names)}) and {kind.name} rows")
    header = _header(source, records[0], kind)
    body = records[1:]
    miscounted = [(line, cells) for line, cells in body if len(cells) != len(header)]
    lines = re.split(r"\r\n|\r|\n", text) if miscounted else []   # the lines as the csv reader counts them
    problems = [_count_problem(lines[line - 1], separator, header, line, cells) for line, cells in miscounted]
    if problems:
        raise CsvError(source, problems)
    return CsvFile(source, separator, header, body)


def _separator(text: str, source: str) -> str:
    """The header's separator: `;` when the header holds `;` and no `,`; else `,`."""
    first = next((line for line in text.splitlines() if line.strip()), "")
    found = [separator for separator in SEPARATORS if separator in first]
    if len(found) > 1:
        raise refuse(source, "the header holds both ',' and ';'", "separate the columns with one of them", line=1)
    return found[0] if found else ","


def _records(text: str, source: str, separator: str, kind: CsvKind) -> list[tuple[int, list[str]]]:
    """Every non-blank record with the line it starts on (cells stripped, unless the kind keeps them)."""
    reader = csv.reader(io.StringIO(text, newline=None), delimiter=separator, strict=True)
    records, start = [], 1
    try:
        for record in reader:
            if reader.line_num > start and not kind.multiline:
                raise refuse(source, f"a quote opened on this line is closed only on line {reader.line_num}",
                             f"close it on line {start} (a cell holds no line break)", line=start)
            if any(cell.strip() for cell in record):
                records.append((start, [cell.strip() for cell in record] if kind.strip else record))
            start = reader.line_num + 1
    except csv.Error as error:
        spans = not kind.multiline and reader.line_num > start   # a quote ran on into the next lines
        raise refuse(source, *_csv_problem(error, spans), line=start) from None
    return records


def _csv_problem(error: csv.Error, spans: bool = False) -> tuple[str, str]:
    if "unexpected end of data" in str(error):
        return "a quote opened here is never closed", "close it (a quote inside a cell is written \"\")"
    if spans:
        return "a quote opened on this line is not closed on it", "close it (a quote inside a cell is written \"\")"
    return f"not valid CSV ({error})", "save it again as CSV"


def _header(source: str, record: tuple[int, list[str]], kind: CsvKind) -> list[str]:
    """The column names of the header (lower case), checked against the kind's declared columns."""
    line, names = record[0], [cell.strip().lower() for cell in record[1]]
    unknown = [name for name in names if name and name not in kind.names]
    twice = sorted({name for name in names if name and names.count(name) > 1})
    missing = [column.name for column in kind.columns
               if (column.required or (kind.every_column and not column.header_optional)) and column.name not in names]
    problems = [Problem(line, None, f"unknown column(s) {', '.join(unknown)}",
                        f"use the columns {', '.join(kind.names)}")] if unknown else []
    problems += [Problem(line, None, f"column(s) named twice: {', '.join(twice)}",
                         "name each column once")] if twice else []
    problems += [Problem(line, None, f"missing required column(s) {', '.join(missing)}",
                         f"add them to the header ({', '.join(kind.names)})")] if missing else []
    if problems:
        raise CsvFileError("; ".join(problem.said(source) for problem in problems))
    return names


def _count_problem(raw: str, separator: str, header: list[str], line: int, cells: list[str]) -> Problem:
    """A record with another cell count than the header's: its values would land in the wrong columns."""
    todo = "give one cell per column (an empty cell for a value not given); quote a cell that holds " \
           f"'{separator}'"
    if separator == "," and len(cells) > len(header) and SPLIT_DECIMAL.search(raw):
        todo = ("a value like 2,5 looks like a decimal comma that split into two cells: write 2.5, or save "
                "the file with ';' between the columns")
    return Problem(line, None, f"{len(cells)} cells, but the header names {len(header)} columns", todo)
