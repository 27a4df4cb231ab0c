"""Template rows as data: one NC line with the expressions that compute and decide it
(design notes §4), a class's assembled template with its content hash, and the CSV form
engineers export, edit and import."""
from __future__ import annotations

import csv
import hashlib
import io
import json
import re
from collections.abc import Mapping
from dataclasses import astuple, dataclass, field
from functools import cached_property
from pathlib import Path

from ..errors import EngineError, csv_problem

CSV_COLUMNS = ("id", "t", "n", "p_calc", "s", "o", "p_emit")
MODULE_ORDER = ("main", "prep", "sync", "shift", "cutcond", "cutmotion")   # the module types, in program order
EXPRESSION_COLUMNS = ("p_calc", "s", "o", "p_emit")


@dataclass(frozen=True)
class TemplateRow:
    id: int
    t: str
    n: int
    p_calc: str | None
    s: str | None
    o: str | None
    p_emit: str | None


@dataclass(frozen=True)
class Template:
    gear_class: str
    version: int
    rows: tuple[TemplateRow, ...]
    # SQL condition text → its stored Python translation (engine.templates.translations)
    translations: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)
    draft: bool = field(default=False, compare=False)   # not a released version (engine.templates.versions)

    @cached_property
    def cache_key(self) -> tuple:
        """What a compiled template depends on: class, version, rows and the stored translations of
        its SQL conditions (which the gate checks again when they change)."""
        return self.gear_class, self.version, self.hash, frozenset(self.translations.items())

    @cached_property
    def hash(self) -> str:
        """Content hash of the assembled rows: what a program records next to the version."""
        return rows_hash(self.rows)


def rows_hash(rows) -> str:
    payload = json.dumps([astuple(row) for row in rows], separators=(",", ":"))
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


def export_csv(template: Template) -> str:
    """The assembled template as CSV: id,t,n,p_calc,s,o,p_emit (absent = empty cell)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for row in template.rows:
        writer.writerow(["" if value is None else value for value in astuple(row)])
    return buffer.getvalue()


MAX_CSV_BYTES = 32 << 20   # a template of 100,000 NC lines exports to about 10 MB
# A line inside a cell that starts like a template row: the cell swallowed the rows after it
# (a quote left open). An `s` cell may hold line breaks, but never a line like this.
ROW_START = re.compile(r"\n\s*\d+\s*,\s*(" + "|".join(MODULE_ORDER) + r")\s*,")


def read_csv(path: Path | str) -> list[TemplateRow]:
    """Template rows from a CSV file; every problem names the line."""
    path = Path(path)
    try:
        if path.stat().st_size > MAX_CSV_BYTES:
            raise EngineError(f"{path}: {path.stat().st_size} bytes, more than a template CSV may hold "
                              f"({MAX_CSV_BYTES} bytes); is it a template?")
        data = path.read_bytes()
    except OSError as error:
        raise EngineError(f"cannot read {path}: {error.strerror}") from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        raise EngineError(f"{path} line {line}: not UTF-8 text (byte 0x{data[error.start]:02x} at offset "
                          f"{error.start}); save the file as UTF-8") from None
    return parse_csv(text, source=str(path))


def parse_csv(text: str, source: str = "template CSV") -> list[TemplateRow]:
    """Rows of a template CSV, read strictly: a quote left open is refused at the line where it
    opens, not read on to the end of the file (which would lose every row after it)."""
    if "\x00" in text:
        raise EngineError(f"{source} line {text.count(chr(10), 0, text.index(chr(0))) + 1}: holds a NUL "
                          "character; a template is text")
    reader, start = csv.reader(io.StringIO(text), strict=True), 1
    try:
        header = tuple(next(reader, ()))
        if set(header) != set(CSV_COLUMNS) or len(header) != len(CSV_COLUMNS):
            raise EngineError(f"{source}: columns must be {','.join(CSV_COLUMNS)}; found {','.join(header)}")
        rows, seen, start = [], set(), reader.line_num + 1
        for cells in reader:
            if cells:
                row = _row_from_record(_record(header, cells), source, start)
                if row.id in seen:
                    raise EngineError(f"{source} line {start}: row id {row.id} appears twice")
                seen.add(row.id)
                rows.append(row)
            start = reader.line_num + 1
    except csv.Error as error:
        raise EngineError(f"{source} line {start}: {csv_problem(error)}") from None
    if not rows:
        raise EngineError(f"{source} has no template rows")
    return sorted(rows, key=lambda row: row.id)


def _record(header: tuple, cells: list[str]) -> dict:
    """The cells by column (missing ones None); extra cells under None, as csv.DictReader does."""
    record = dict(zip(header, cells))
    record.update((column, None) for column in header[len(cells):])
    if len(cells) > len(header):
        record[None] = cells[len(header):]
    return record


def _row_from_record(record: dict, source: str, line: int) -> TemplateRow:
    if None in record:
        raise EngineError(f"{source} line {line}: more cells than columns (quote cells with commas)")
    try:
        row_id, n = int(record["id"]), int(record["n"] or 1)
    except ValueError:
        raise EngineError(f"{source} line {line}: id and n must be whole numbers, "
                          f"got id={record['id']!r} n={record['n']!r}") from None
    texts = {column: (record[column] if record[column] and record[column].strip() else None)
             for column in EXPRESSION_COLUMNS}
    swallowed = next((ROW_START.search(text) for text in texts.values() if text and ROW_START.search(text)), None)
    if swallowed:
        raise EngineError(f"{source} line {line}: a cell runs on into what looks like a row "
                          f"({swallowed.group().strip()!r}…): a quote opened on this line is not closed")
    return TemplateRow(row_id, (record["t"] or "").strip(), n, texts["p_calc"], texts["s"],
                       texts["o"], texts["p_emit"])
