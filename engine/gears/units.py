"""Further toothed units of multi-unit (duplex) gears, from CSV: gear_id, unit, teeth,
face_width, tip_diameter, root_diameter, z_top. Unit 1 is the gear row itself; unit 2 is
given here (no class cuts a third unit: class duplex cuts two per set-up). All rows are
checked first; a file with any bad row stores nothing. The units of every gear in the file
replace that gear's units."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..csv_reader import Column, CsvKind, Problem, parse_number, parse_positive_whole, read_csv_file
from ..db.replacing import Change, jobs_of, refuse_held, said
from ..errors import EngineError
from .classify import classify
from .gear_geometry import diameter_problems
from .gear_import import POSITIVE, GearImportError, derived_diameters
from .gear_store import JOBS_OF_GEARS
from .models import ancestry

if TYPE_CHECKING:
    from ..db.connection import Connection

# The class that cuts further units (engine/hobbing/duplex.py), and the last unit it cuts: two units
# per set-up, the gear row and unit 2. A third toothing is cut in a set-up of its own.
UNIT_CLASS = "duplex"
LAST_UNIT = 2

UNIT_COLUMNS: tuple[Column, ...] = (
    Column("gear_id", parse_positive_whole, required=True),
    Column("unit", parse_positive_whole, required=True, check=lambda v: v == LAST_UNIT,
           rule=f"must be {LAST_UNIT}: unit 1 is the gear row, and class {UNIT_CLASS} (the only class that cuts "
                f"further units) cuts two per set-up",
           hint="write 2, and cut a third toothing in a set-up of its own"),
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
    return len(_import(conn, Path(path), only_gears))


def import_units_noting(conn: Connection, path: str | Path) -> tuple[int, list[str]]:
    """`import_units`, and what the stored units leave to do (`unit_notes`)."""
    units = _import(conn, Path(path), None)
    return len(units), unit_notes(conn, {unit["gear_id"] for unit in units})


def _import(conn: Connection, path: Path, only_gears: set[int] | None) -> list[dict]:
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
    _store(conn, path, [unit for _, unit in units])
    return [unit for _, unit in units]


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


STORED_UNITS = ("SELECT gear_id, unit, teeth, face_width, tip_diameter, root_diameter, z_top FROM gear_unit "
                "WHERE gear_id = ANY(%s) ORDER BY gear_id, unit")
LOCK_GEARS = "SELECT id FROM gear WHERE id = ANY(%s) ORDER BY id FOR UPDATE"


def _store(conn: Connection, path: Path, units: list[dict]) -> None:
    """The units of each gear of the file replace its units, in one transaction; the units of a gear
    a stored job was made from only by the same units (engine.db.replacing): its programs were
    proved on them (the duplex model cuts them, the simulation follows them)."""
    with conn.transaction():
        gear_ids = sorted({unit["gear_id"] for unit in units})
        conn.execute(LOCK_GEARS, (gear_ids,))
        changes = _unit_changes(conn, gear_ids, units)
        refuse_held(path, "gear", changes, jobs_of(conn, JOBS_OF_GEARS, [change.key for change in changes]))
        conn.execute("DELETE FROM gear_unit WHERE gear_id = ANY(%s)", (gear_ids,))
        for unit in units:
            conn.execute(INSERT_UNIT, tuple(unit[column.name] for column in UNIT_COLUMNS))


def _unit_changes(conn: Connection, gear_ids: list[int], units: list[dict]) -> list[Change]:
    """Per gear whose units the file changes: its units as stored → as the file gives them."""
    stored: dict[int, list[tuple]] = {gear_id: [] for gear_id in gear_ids}
    for row in conn.execute(STORED_UNITS, (gear_ids,)):
        stored[row[0]].append(row[1:])
    given: dict[int, list[tuple]] = {gear_id: [] for gear_id in gear_ids}
    for unit in sorted(units, key=lambda unit: unit["unit"]):
        given[unit["gear_id"]].append(tuple(unit[column.name] for column in UNIT_COLUMNS[1:]))
    return [Change(gear_id, "further units", _units_said(stored[gear_id]), _units_said(given[gear_id]))
            for gear_id in gear_ids if stored[gear_id] != given[gear_id]]


def _units_said(units: list[tuple]) -> str | None:
    """`unit 2 (z 19, b 15, da 42, df 37.5, z_top -75)`; None for no units."""
    return "; ".join(f"unit {unit} (z {teeth}, b {said(width)}, da {said(tip)}, df {said(root)}, z_top {said(top)})"
                     for unit, teeth, width, tip, root, top in units) or None


GEAR_CLASS = ("SELECT gear_class, cone_angle, crowning, helix_angle, material, "
              "(SELECT count(*) FROM gear_unit u WHERE u.gear_id = gear.id) FROM gear WHERE id = %s")


def unit_notes(conn: Connection, gear_ids: set[int]) -> list[str]:
    """What the units just stored leave to do, one line each: a gear whose class does not cut
    further units (only UNIT_CLASS and the classes under it do: the models of the others read the gear
    row alone). (A gear with stored jobs keeps its units: _store.)"""
    notes = []
    for gear_id in sorted(gear_ids):
        gear = tuple(conn.execute(GEAR_CLASS, (gear_id,)).fetchone() or ())   # the units' gear exists
        if gear[0] and UNIT_CLASS not in ancestry(conn, gear[0]):
            notes.append(f"gear {gear_id}: class {gear[0]} does not cut further units; " + _what_to_do(gear_id, gear))
    return notes


def _what_to_do(gear_id: int, gear: tuple) -> str:
    """A spur gear can become UNIT_CLASS (spur units of one module); a helical one has no class."""
    _, cone, crowning, helix, material, count = gear
    if helix:
        return (f"class {UNIT_CLASS} cuts spur units only (β = {helix:g}°): no program cuts these units; "
                f"cut the further toothing in a set-up of its own, as a gear of its own")
    tree = classify({"gear_id": gear_id, "cone_angle": cone, "crowning": crowning, "helix_angle": helix,
                     "material": material, "units": count}).gear_class
    leave = f" (or leave it empty: the tree classes it {tree})" if tree == UNIT_CLASS else ""
    return (f"give gear_class {UNIT_CLASS}{leave} and import the gear again with "
            f"`engine gears import FILE.csv --replace`")
