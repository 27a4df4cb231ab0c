"""The workpiece materials (issue 31, table material): each with its group, its hardness range
(HB) and the cutting speeds of docs/reference/hobbing.md §C by hob material and coating
(engine.gears.speed_table reads them, loaded onto the gear record). List them, show one, import
a CSV of them (the list's CSV is what the import reads), and the refusal of a gear whose
material the table lacks: a material is never guessed, its speeds bound the hob's (§C)."""
from __future__ import annotations

from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import psycopg
from psycopg import sql

from ..csv_reader import Column as CsvColumn
from ..csv_reader import CsvError, CsvKind, Problem, parse_number, parse_text, read_cell, read_csv_file
from ..db.connection import scalar
from ..db.listing import exact_records
from ..errors import EngineError
from .known_materials import material_names, unknown_material

if TYPE_CHECKING:
    from ..db.connection import Connection

POSITIVE: dict[str, Any] = dict(check=lambda value: value > 0, rule="must be greater than 0")
SPEED: dict[str, Any] = dict(unit="m/min", required=True, **POSITIVE)
# The columns of table material, in its order: `materials list --csv` writes them, `import` reads them.
MATERIAL_COLUMNS: tuple[CsvColumn, ...] = (
    CsvColumn("name", parse_text, required=True, check=lambda value: len(value) <= 40, rule="is over 40 characters"),
    CsvColumn("material_group", parse_text, required=True),
    CsvColumn("hardness_min", parse_number, required=True, unit="HB", **POSITIVE),
    CsvColumn("hardness_max", parse_number, required=True, unit="HB", **POSITIVE),
    CsvColumn("uncoated_low", parse_number, **SPEED), CsvColumn("uncoated_high", parse_number, **SPEED),
    CsvColumn("coated_low", parse_number, **SPEED), CsvColumn("coated_high", parse_number, **SPEED),
    CsvColumn("carbide_low", parse_number, **SPEED), CsvColumn("carbide_high", parse_number, **SPEED),
    CsvColumn("default_uncoated", parse_number, **SPEED), CsvColumn("default_coated", parse_number, **SPEED),
    CsvColumn("source", parse_text, required=True),
)
COLUMN_NAMES = tuple(column.name for column in MATERIAL_COLUMNS)
MATERIAL_KIND = CsvKind("material", MATERIAL_COLUMNS)
# (low, high) pairs a row must keep in order, and each default within its pair (the database's
# constraints, said per row before the database is asked).
PAIRS = (("hardness_min", "hardness_max"), ("uncoated_low", "uncoated_high"), ("coated_low", "coated_high"),
         ("carbide_low", "carbide_high"))
DEFAULTS_WITHIN = (("default_uncoated", "uncoated_low", "uncoated_high"),
                   ("default_coated", "coated_low", "coated_high"))

_COLUMN_LIST = sql.SQL(", ").join(map(sql.Identifier, COLUMN_NAMES))
# By name ignoring case, byte order (COLLATE "C"): the same list whatever the server's locale.
LIST = sql.SQL('SELECT {} FROM material ORDER BY lower(name) COLLATE "C"').format(_COLUMN_LIST)
ONE = sql.SQL("SELECT {} FROM material WHERE lower(name) = lower(%s)").format(_COLUMN_LIST)
GEARS_OF = "SELECT count(*) FROM gear WHERE lower(btrim(material)) = lower(%s)"
_UPSERT = sql.SQL("INSERT INTO material ({}) VALUES ({}) ON CONFLICT (name) DO UPDATE SET {}").format(
    _COLUMN_LIST, sql.SQL(", ").join(sql.Placeholder() * len(COLUMN_NAMES)), sql.SQL(", ").join(
        sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(name)) for name in COLUMN_NAMES if name != "name"))
TWIN = "SELECT name FROM material WHERE lower(name) = lower(%s) AND name <> %s"


class MaterialImport(msgspec.Struct, frozen=True):
    """What an import did: materials new to the table, and those whose name was there already."""

    added: int
    updated: int


def list_materials(conn: Connection) -> list[dict]:
    """Every material by name (ignoring case), keyed by the CSV columns, each value as stored
    (every digit): what `engine materials import FILE --replace` takes back unchanged."""
    return exact_records(conn.execute(LIST))


def show_material(conn: Connection, name: str) -> dict:
    """The material of that name (ignoring case) with the count of stored gears of it; EngineError
    naming the known ones, closest first, when there is none."""
    found = exact_records(conn.execute(ONE, (name,)))
    if not found:
        raise EngineError(unknown_material(f"material {name!r}", name, material_names(conn)))
    return {**found[0], "gear_count": scalar(conn.execute(GEARS_OF, (found[0]["name"],)))}


def read_materials(path: str | Path) -> list[tuple[int, dict[str, Any]]]:
    """(line, material) of every row of the CSV file, each checked; CsvError listing every
    problem of every row (header = line 1)."""
    file = read_csv_file(path, MATERIAL_KIND)
    if not file.records:
        raise EngineError(f"{path}: no material rows; give one material per line under the header")
    rows: list[tuple[int, dict[str, Any]]] = []
    problems: list[Problem] = []
    first_line: dict[str, int] = {}   # a name in lower case -> the line it is first on
    for line, cells in file.rows():
        material: dict[str, Any] = {}
        for column in MATERIAL_COLUMNS:
            value, problem = read_cell(column, cells.get(column.name, "").strip(), line, file.separator)
            material[column.name] = None if problem else value
            problems += [problem] if problem else []
        problems += _row_problems(line, material, first_line)
        rows.append((line, material))
    if problems:
        raise CsvError(path, problems)
    return rows


def _row_problems(line: int, material: dict[str, Any], first_line: dict[str, int]) -> list[Problem]:
    """Lows above highs, defaults outside their range, a name given twice (ignoring case)."""
    problems = [Problem(line, high, f"{material[high]} is below {low} {material[low]}", f"give {low} ≤ {high}")
                for low, high in PAIRS if _numbers(material, low, high) and material[low] > material[high]]
    problems += [Problem(line, name, f"{material[name]} is outside {material[low]}–{material[high]} m/min",
                         f"give a {name.replace('_', ' ')} within {low}…{high}")
                 for name, low, high in DEFAULTS_WITHIN if _numbers(material, name, low, high)
                 and not material[low] <= material[name] <= material[high]]
    folded = (material["name"] or "").lower()
    if folded in first_line:
        problems.append(Problem(line, "name", f"{material['name']} is already on line {first_line[folded]} "
                                "(names that differ only in case name one material)", "give each material once"))
    elif folded:
        first_line[folded] = line
    return problems


def _numbers(material: dict[str, Any], *names: str) -> bool:
    return all(isinstance(material[name], Decimal) for name in names)


def import_materials(conn: Connection, path: str | Path, *, replace: bool = False) -> MaterialImport:
    """Insert or update (by name) every material of the CSV file, all or nothing. `replace`: the
    file must give every column (each stored material is replaced whole). A stored material of
    the same name in another case is refused (the engine matches names ignoring case)."""
    lined = read_materials(path)
    given = read_csv_file(path, MATERIAL_KIND).header
    left_out = [name for name in COLUMN_NAMES if name not in given]
    if replace and left_out:
        raise EngineError(f"{path}: --replace replaces each stored material whole, but the file leaves out "
                          f"{', '.join(left_out)}; nothing imported: give every column (`engine materials list "
                          "--csv` writes them)")
    twins = [Problem(line, "name", f"{m['name']} is material {twin[0]} of the table (names that differ only in "
                     "case name one material)", f"write {twin[0]}")
             for line, m in lined if (twin := conn.execute(TWIN, (m["name"], m["name"])).fetchone())]
    if twins:
        raise CsvError(path, twins)
    names = [material["name"] for _, material in lined]
    try:
        with conn.transaction():
            stored = scalar(conn.execute("SELECT count(*) FROM material WHERE name = ANY(%s)", (names,)))
            with conn.cursor() as cursor:
                cursor.executemany(_UPSERT, [[material[name] for name in COLUMN_NAMES] for _, material in lined])
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"{path}: the database refused the materials "
                          f"({error.diag.message_primary or error}); nothing imported") from error
    return MaterialImport(added=len(names) - stored, updated=stored)
