"""Template rows as data: one NC line with the expressions that compute and decide it
(design notes §4), a class's assembled template with its content hash, and the CSV form
engineers export, edit and import."""
from __future__ import annotations

import csv
import hashlib
import io
import json
from collections.abc import Mapping
from dataclasses import astuple, dataclass, field
from functools import cached_property
from pathlib import Path

from ..errors import EngineError

CSV_COLUMNS = ("id", "t", "n", "p_calc", "s", "o", "p_emit")
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


def read_csv(path: Path | str) -> list[TemplateRow]:
    """Template rows from a CSV file; every problem names the line."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as error:
        raise EngineError(f"cannot read {path}: {error.strerror}") from None
    return parse_csv(text, source=str(path))


def parse_csv(text: str, source: str = "template CSV") -> list[TemplateRow]:
    reader = csv.DictReader(io.StringIO(text))
    header = tuple(reader.fieldnames or ())
    if set(header) != set(CSV_COLUMNS):
        raise EngineError(f"{source}: columns must be {','.join(CSV_COLUMNS)}; found {','.join(header)}")
    rows, seen = [], set()
    for record in reader:
        row = _row_from_record(record, source, reader.line_num)
        if row.id in seen:
            raise EngineError(f"{source} line {reader.line_num}: row id {row.id} appears twice")
        seen.add(row.id)
        rows.append(row)
    if not rows:
        raise EngineError(f"{source} has no template rows")
    return sorted(rows, key=lambda row: row.id)


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
    return TemplateRow(row_id, (record["t"] or "").strip(), n, texts["p_calc"], texts["s"],
                       texts["o"], texts["p_emit"])
