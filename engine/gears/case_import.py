"""The machining history as a file and back (`engine cases list --csv`, `engine cases import`,
issue 31): the cases' columns of the seed file (seed_templates/cases.csv) and, first, their id.

A row with an id is that case: refused if stored, unless --replace, which replaces it (each changed
field said old → new); a row without one is a new case. A case confirmed from a job records what
that job ran: it is replaced by itself only (engine.db.replacing). The job and the time of a case
are the database's own record of where it came from, not a file's, and are not in the file. All
rows are checked first and stored in one transaction; the ids given move the sequence past them,
so a case confirmed later takes a new id."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import psycopg
from psycopg import sql

from ..csv_reader import (
    Column,
    CsvError,
    CsvKind,
    Problem,
    parse_number,
    parse_positive_whole,
    parse_text,
    parse_whole,
    read_csv_file,
)
from ..db.listing import exact_records
from ..db.replacing import Change, changed_fields, refuse_held
from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection

FEATURE_COLUMNS = ("module", "teeth", "material", "hardness", "quality_grade", "hob_material",
                   "hob_coating", "hob_starts", "hob_tip_diameter")
VALUE_COLUMNS = ("hob_speed", "axial_feed", "radial_feed")   # r/min, mm/min, mm/min
CASE_FIELDS = (*FEATURE_COLUMNS, "cut", *VALUE_COLUMNS, "source")
OPTIONAL = ("hob_coating", "source", "hardness", "quality_grade")
EMPTY_TEXT = ("hob_coating", "source")   # an empty cell is the empty text the column holds by default
_TYPES = {"module": (parse_number, "mm"), "teeth": (parse_positive_whole, ""), "hardness": (parse_number, "HB"),
          "quality_grade": (parse_whole, ""), "hob_starts": (parse_positive_whole, ""),
          "hob_tip_diameter": (parse_number, "mm"), "hob_speed": (parse_number, "r/min"),
          "axial_feed": (parse_number, "mm/min"), "radial_feed": (parse_number, "mm/min")}
CASE_KIND = CsvKind("case", tuple(
    Column(name, _TYPES.get(name, (parse_text, ""))[0], required=name not in OPTIONAL,
           unit=_TYPES.get(name, (parse_text, ""))[1]) for name in CASE_FIELDS))
CASE_FILE_KIND = CsvKind("case", (Column("id", parse_positive_whole), *CASE_KIND.columns))
FILE_COLUMNS = CASE_FILE_KIND.names

_FIELDS = sql.SQL(", ").join(map(sql.Identifier, CASE_FIELDS))
EXPORT = sql.SQL("SELECT id, {} FROM cutting_case ORDER BY id").format(_FIELDS)
LOCKED = sql.SQL("SELECT id, job_id, {} FROM cutting_case WHERE id = ANY(%s) ORDER BY id FOR UPDATE").format(_FIELDS)
UPSERT = sql.SQL("INSERT INTO cutting_case (id, {}) VALUES (%(id)s, {}) ON CONFLICT (id) DO UPDATE SET {}").format(
    _FIELDS, sql.SQL(", ").join(map(sql.Placeholder, CASE_FIELDS)),
    sql.SQL(", ").join(sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(name)) for name in CASE_FIELDS))
INSERT = sql.SQL("INSERT INTO cutting_case ({}) VALUES ({})").format(
    _FIELDS, sql.SQL(", ").join(map(sql.Placeholder, CASE_FIELDS)))
# the next id the sequence gives must be above every stored one
PAST_IDS = ("SELECT setval('cutting_case_id_seq', max(id)) FROM cutting_case HAVING max(id) >= "
            "(SELECT CASE WHEN is_called THEN last_value + 1 ELSE last_value END FROM cutting_case_id_seq)")


def export_cases(conn: Connection) -> list[dict[str, Any]]:
    """Every case by id as `engine cases import` reads it: each value as stored (every digit)."""
    return exact_records(conn.execute(EXPORT))


def read_cases(path: str | Path, kind: CsvKind = CASE_FILE_KIND) -> list[tuple[int, dict[str, Any]]]:
    """(line, case) of every row of the file, checked; CsvError listing every problem."""
    file = read_csv_file(path, kind)
    if not file.records:
        raise EngineError(f"{path}: no case rows; give one case per line under the header")
    rows, problems = [], []
    for line, record in file.rows():
        values = {column.name: file.cell(column, record.get(column.name, ""), line) for column in kind.columns}
        problems += [problem for _, problem in values.values() if problem]
        rows.append((line, {name: "" if value is None and name in EMPTY_TEXT else value
                            for name, (value, _) in values.items()}))
    problems += _twice(rows)
    if problems:
        raise CsvError(path, problems)
    return rows


def _twice(rows: list[tuple[int, dict[str, Any]]]) -> list[Problem]:
    first: dict[int, int] = {}
    problems = []
    for line, case in rows:
        if case.get("id") is not None and first.setdefault(case["id"], line) != line:
            problems.append(Problem(line, "id", f"{case['id']} is already on line {first[case['id']]}",
                                    "give each case once"))
    return problems


def import_cases(conn: Connection, path: str | Path, *, replace: bool = False) -> tuple[int, int, list[Change]]:
    """Store every case of the file, all or nothing: (added, replaced, changes of the replaced)."""
    rows = read_cases(path)
    given = [case for _, case in rows if case["id"] is not None]
    try:
        with conn.transaction():
            stored = {row["id"]: row for row in exact_records(conn.execute(LOCKED, ([case["id"] for case in given],)))}
            if not replace:
                _refuse_stored(path, rows, stored)
            changes = changed_fields(stored, given, "id", CASE_FIELDS)
            jobs = {key: [row["job_id"]] for key, row in stored.items() if row["job_id"] is not None}
            refuse_held(path, "case", changes, jobs, relation="it records what {jobs} ran")
            with conn.cursor() as cursor:
                cursor.executemany(UPSERT, given)
                conn.execute(PAST_IDS)
                cursor.executemany(INSERT, [case for _, case in rows if case["id"] is None])
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"{path}: the database refused the cases "
                          f"({error.diag.message_primary or error}); nothing imported") from error
    return len(rows) - len(stored), len(stored), changes


def _refuse_stored(path: str | Path, rows: list[tuple[int, dict[str, Any]]], stored: dict) -> None:
    problems = [Problem(line, "id", f"case {case['id']} already exists",
                        "leave the id empty for a new case, or import with --replace to replace it "
                        "(the changes are printed)")
                for line, case in rows if case["id"] in stored]
    if problems:
        raise CsvError(path, problems)
