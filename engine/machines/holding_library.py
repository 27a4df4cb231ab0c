"""The work-holding library (issue 29): list it, import a CSV of work-holdings. As the hob library
(engine.gears.hob_library): every cell goes through the column parsers of HOLDING_COLUMNS, then
the cross-column checks; an import is all or nothing, every problem reported with the physical
line number in the file (header = line 1), and only a good file is stored."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import psycopg
from msgspec.structs import asdict
from psycopg import sql

from ..csv_reader import CellError, Column, CsvError, CsvKind, Problem, declare, parse_number, read_cell, read_csv_file
from ..db.listing import exact_records
from ..db.replacing import changed_fields, jobs_of, refuse_held
from ..errors import EngineError
from ..names import NAME_RULES, is_safe
from .work_holding import KINDS, WorkHolding, load_work_holdings

if TYPE_CHECKING:
    from ..db.connection import Connection


class HoldingImport(msgspec.Struct, frozen=True):
    """What an import did: work-holdings new to the library, and those whose id was there already."""

    added: int
    updated: int


def parse_holding_id(cell: str) -> str:
    """The id is printed in the program's `; FIXTURE …` comment: a safe name like a hob's."""
    if not is_safe("hob", cell):
        raise CellError(f"is not a safe work-holding id: use {NAME_RULES['hob'].rule}")
    return cell


def parse_kind(cell: str) -> str:
    if cell.lower() not in KINDS:
        raise CellError(f"is not one of {', '.join(KINDS)}")
    return cell.lower()


def parse_machine(cell: str) -> str:
    if not is_safe("machine", cell):
        raise CellError(f"is not a safe machine name: use {NAME_RULES['machine'].rule}")
    return cell


declare(parse_holding_id, "work-holding id", "write an id like A-D12-H40")
declare(parse_kind, "work-holding kind", f"write one of {', '.join(KINDS)}")
declare(parse_machine, "machine", "write a machine name of `engine machines list`, or leave it empty for any")

POSITIVE: dict[str, Any] = dict(check=lambda value: value > 0, rule="must be greater than 0")
# In the order of the fields of work_holding.WorkHolding (and of seed_templates/work_holdings.csv).
HOLDING_COLUMNS: tuple[Column, ...] = (
    Column("id", parse_holding_id, required=True),
    Column("kind", parse_kind, required=True),
    Column("diameter", parse_number, required=True, unit="mm", **POSITIVE),
    Column("height", parse_number, required=True, unit="mm", **POSITIVE),
    Column("tailstock_diameter", parse_number, unit="mm", check=lambda value: value >= 0, rule="is negative"),
    Column("machine", parse_machine),
)
COLUMN_NAMES = tuple(column.name for column in HOLDING_COLUMNS)
HOLDING_KIND = CsvKind("work-holding", HOLDING_COLUMNS)
DEFAULTS = {"tailstock_diameter": 0}
assert COLUMN_NAMES == WorkHolding.__struct_fields__, "HOLDING_COLUMNS must follow WorkHolding"


def parse_holding(cells: dict[str, str], line: int | None = None,
                  separator: str = ",") -> tuple[dict[str, Any], list[Problem]]:
    """The work-holding of named cells (missing cells are empty) and its problems."""
    holding: dict[str, Any] = {}
    problems: list[Problem] = []
    for column in HOLDING_COLUMNS:
        cell = cells.get(column.name, "").strip()
        value, problem = read_cell(column, cell, line, separator)
        holding[column.name] = DEFAULTS.get(column.name) if not cell else (None if problem else value)
        if problem:
            problems.append(problem)
    return holding, problems


def list_holdings(conn: Connection) -> list[dict]:
    """Every work-holding of the library by id, keyed by the CSV columns (what `import` reads back),
    whole millimetres as whole numbers (12, not 12.0)."""
    return [{key: _whole(value) for key, value in asdict(holding).items()} for holding in load_work_holdings(conn)]


_COLUMN_LIST = sql.SQL(", ").join(map(sql.Identifier, COLUMN_NAMES))
EXPORT = sql.SQL("SELECT {} FROM work_holding ORDER BY id").format(_COLUMN_LIST)


def export_holdings(conn: Connection) -> list[dict]:
    """Every work-holding of the library by id as `engine fixtures import` reads it: each value as
    stored (every digit of its numbers)."""
    return exact_records(conn.execute(EXPORT))


def _whole(value: Any) -> Any:
    return int(value) if isinstance(value, float) and value.is_integer() else value


def read_holdings(path: str | Path) -> list[dict[str, Any]]:
    """Every work-holding of the CSV file at `path`, checked; CsvError listing every problem of
    every row, or EngineError."""
    holdings, problems = _read(path)
    if problems:
        raise CsvError(path, problems)
    return [holding for _, holding in holdings]


def _read(path: str | Path) -> tuple[list[tuple[int, dict[str, Any]]], list[Problem]]:
    """(line, work-holding) of every row of the file and the problems of its cells and ids."""
    file = read_csv_file(path, HOLDING_KIND)
    if not file.records:
        raise EngineError(f"{path}: no work-holding rows; give one work-holding per line under the header")
    holdings, problems = [], []
    first_line: dict[str, tuple[int, str]] = {}   # id in upper case -> (line, id) where it is first
    for line, cells in file.rows():
        holding, row_problems = parse_holding(cells, line, file.separator)
        folded = holding["id"].upper() if holding["id"] is not None else None
        if folded in first_line:
            earlier, earlier_id = first_line[folded]
            case = f" as {earlier_id} (ids that differ only in case name one work-holding)" \
                if earlier_id != holding["id"] else ""
            row_problems.append(Problem(line, "id", f"{holding['id']} is already on line {earlier}{case}",
                                        "give each work-holding once"))
        elif folded is not None:
            first_line[folded] = (line, holding["id"])
        problems += row_problems
        holdings.append((line, holding))
    return holdings, problems


_UPSERT = sql.SQL("INSERT INTO work_holding ({}) VALUES ({}) ON CONFLICT (id) DO UPDATE SET {}").format(
    _COLUMN_LIST, sql.SQL(", ").join(sql.Placeholder() * len(COLUMN_NAMES)), sql.SQL(", ").join(
        sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(name)) for name in COLUMN_NAMES if name != "id"))
TWIN = "SELECT id FROM work_holding WHERE upper(id) = upper(%s) AND id <> %s"
MACHINE_KIND = "SELECT kind FROM machine WHERE name = %s"


def _library_problems(conn: Connection, holdings: list[tuple[int, dict[str, Any]]]) -> list[Problem]:
    """Per row, what the database says against it: an id that is a stored work-holding's in another
    case, a machine that does not exist or is not a hobber (a work-holding stands on a hobber's
    table under the gear; a lathe's work-holding is its chuck and jaws, docs/design.md §8)."""
    problems = []
    for line, holding in holdings:
        twin = conn.execute(TWIN, (holding["id"], holding["id"])).fetchone() if holding["id"] else None
        if twin:
            problems.append(Problem(line, "id", f"{holding['id']} is work-holding {twin[0]} of the library (ids "
                                    "that differ only in case name one work-holding)", f"write {twin[0]}"))
        machine = holding["machine"]
        kind = conn.execute(MACHINE_KIND, (machine,)).fetchone() if machine else ("hobber",)
        if kind is None:
            problems.append(Problem(line, "machine", f"machine {machine} does not exist",
                                    "write a machine of `engine machines list`, or leave it empty for any hobber"))
        elif kind[0] != "hobber":
            problems.append(Problem(line, "machine", f"machine {machine} is a {kind[0]}, not a hobber",
                                    "write a hobbing machine, or leave it empty for any hobber"))
    return problems


JOBS_OF_HOLDINGS = ("SELECT work_holding_id, array_agg(id ORDER BY id) FROM job WHERE work_holding_id = ANY(%s) "
                    "GROUP BY work_holding_id")
LOCKED = sql.SQL("SELECT {} FROM work_holding WHERE id = ANY(%s) ORDER BY id FOR UPDATE").format(_COLUMN_LIST)


def import_holdings(conn: Connection, path: str | Path, *, replace: bool = False) -> HoldingImport:
    """Insert or update (by id) every work-holding of the CSV file at `path`, all or nothing.
    `replace`: the file must give every column (each stored work-holding is replaced whole). A
    work-holding a stored job is clamped on is changed in no column (engine.db.replacing)."""
    lined, problems = _read(path)
    problems += _library_problems(conn, [(line, holding) for line, holding in lined if holding["id"] is not None])
    if problems:
        raise CsvError(path, problems)
    _refuse_partial(path, replace)
    holdings = [holding for _, holding in lined]
    ids = [holding["id"] for holding in holdings]
    try:
        with conn.transaction():
            stored = {row["id"]: row for row in exact_records(conn.execute(LOCKED, (ids,)))}
            changes = changed_fields(stored, holdings, "id", COLUMN_NAMES[1:])
            refuse_held(path, "work-holding", changes,
                        jobs_of(conn, JOBS_OF_HOLDINGS, [change.key for change in changes]),
                        relation="{jobs} {were} clamped on it")
            with conn.cursor() as cursor:
                cursor.executemany(_UPSERT, [[holding[name] for name in COLUMN_NAMES] for holding in holdings])
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"{path}: the database refused the work-holdings "
                          f"({error.diag.message_primary or error}); nothing imported") from error
    return HoldingImport(added=len(ids) - len(stored), updated=len(stored))


def _refuse_partial(path: str | Path, replace: bool) -> None:
    """--replace replaces each stored work-holding whole: a column the file leaves out is refused,
    not set to its default."""
    given = read_csv_file(path, HOLDING_KIND).header
    left_out = [name for name in COLUMN_NAMES if name not in given]
    if replace and left_out:
        raise EngineError(f"{path}: --replace replaces each stored work-holding whole, but the file leaves out "
                          f"{', '.join(left_out)}; nothing imported: give every column (`engine fixtures list "
                          "--csv` writes them)")
