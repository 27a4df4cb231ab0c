"""Further toothed units of multi-unit (duplex) gears, from CSV: gear_id, unit, teeth,
face_width, tip_diameter, root_diameter, z_top. Unit 1 is the gear row itself; unit 2
and on are given here. All rows are checked first; a file with any bad row stores nothing.
The units of every gear in the file replace that gear's units."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..csv_reader import Column, CsvKind, Problem, parse_number, parse_positive_whole, read_csv_file
from ..errors import EngineError
from .gear_geometry import diameter_problems
from .gear_import import POSITIVE, GearImportError, derived_diameters

if TYPE_CHECKING:
    from ..db.connection import Connection

UNIT_COLUMNS: tuple[Column, ...] = (
    Column("gear_id", parse_positive_whole, required=True),
    Column("unit", parse_positive_whole, required=True, check=lambda v: v >= 2,
           rule="must be 2 or more (unit 1 is the gear row)"),
    Column("teeth", parse_positive_whole, required=True),
    Column("face_width", parse_number, required=True, unit="mm", **POSITIVE),
    Column("tip_diameter", parse_number, unit="mm", **POSITIVE),
    Column("root_diameter", parse_number, unit="mm", **POSITIVE),
    Column("z_top", parse_number, required=True, check=lambda v: v < 0, unit="mm",
           rule="must be below the gear's top face (Z < 0)"),
)
UNIT_KIND = CsvKind("unit", UNIT_COLUMNS)
INSERT_UNIT = """
INSERT INTO gear_unit (gear_id, unit, teeth, face_width, tip_diameter, root_diameter, z_top)
VALUES (%s, %s, %s, %s, %s, %s, %s)"""


def import_units(conn: Connection, path: str | Path, only_gears: set[int] | None = None) -> int:
    """Store the units of the CSV at `path` (only those of `only_gears` if given); return
    how many. Raises GearImportError listing every problem."""
    path = Path(path)
    file = read_csv_file(path, UNIT_KIND)
    if not file.records:
        raise EngineError(f"{path}: no unit rows; give one unit per line under the header")
    units, problems = [], []
    for line, cells in file.rows():
        unit, row_problems = _parse_unit(file, line, cells)
        problems += row_problems
        if not row_problems and (only_gears is None or unit["gear_id"] in only_gears):
            units.append((line, unit))
    problems += _database_problems(conn, units)
    if problems:
        raise GearImportError(path, problems)
    _store(conn, [unit for _, unit in units])
    return len(units)


def _parse_unit(file, line: int, cells: dict) -> tuple[dict, list[Problem]]:
    unit, problems = {}, []
    for column in UNIT_COLUMNS:
        unit[column.name], problem = file.cell(column, cells.get(column.name, ""), line)
        if problem:
            problems.append(problem)
    return unit, problems


UNIT_GEAR = ("SELECT module, face_width, gear_class IN (SELECT name FROM classes_and_below(ARRAY['cylindrical'])) "
             "FROM gear WHERE id = %s")


def _database_problems(conn: Connection, units: list) -> list[Problem]:
    """Each unit's gear must exist; given diameters of a cylindrical gear's unit (a spur unit of the
    gear's module) must fit the formulas (engine.gears.gear_geometry); the others are completed."""
    problems = []
    for line, unit in units:
        gear = conn.execute(UNIT_GEAR, (unit["gear_id"],)).fetchone()
        if gear is None:
            problems.append(Problem(line, "gear_id", f"gear {unit['gear_id']} does not exist", "import the gear first"))
            continue
        module, face_width, cylindrical = gear
        spur = {**unit, "module": module, "helix_angle": 0, "module_kind": None, "profile_shift": None}
        geometry = [Problem(line, p.column, p.what, p.todo) for p in diameter_problems(spur)] if cylindrical else []
        problems += geometry
        if geometry:
            continue
        if unit["z_top"] > -face_width:
            problems.append(Problem(line, "z_top", f"{unit['z_top']} lies inside unit 1 (Z0…{-face_width})",
                                    "give a Z below the gear's first unit"))
        unit["tip_diameter"], unit["root_diameter"] = derived_diameters(
            module, unit["teeth"], 0, unit["tip_diameter"], unit["root_diameter"])
        if unit["root_diameter"] <= 0 or unit["root_diameter"] >= unit["tip_diameter"]:
            problems.append(Problem(line, "root_diameter", f"{unit['root_diameter']:g} does not fit tip diameter "
                                                           f"{unit['tip_diameter']:g}", "give both diameters"))
    return problems


def _store(conn: Connection, units: list[dict]) -> None:
    with conn.transaction():
        gear_ids = sorted({unit["gear_id"] for unit in units})
        conn.execute("DELETE FROM gear_unit WHERE gear_id = ANY(%s)", (gear_ids,))
        for unit in units:
            conn.execute(INSERT_UNIT, tuple(unit[column.name] for column in UNIT_COLUMNS))
