"""Workpieces from a gear CSV (design notes §9 columns).

Every row is read and checked first; only when the whole file is good are all its gears
upserted, in one transaction. A file with any bad row stores nothing and reports every
problem, one line each, with the physical line number in the file (header = line 1).
Numbers are kept as Decimal, so they are stored exactly as written.
"""
from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any, Callable, Iterable

import psycopg
from psycopg import sql

from ..errors import EngineError, csv_problem
from ..names import NAME_RULES, is_safe, shown
from .classify import Classification, classify, not_installed_message
from .module_kind import MODULE_KINDS, check_module_kind as _check_module_kind
from .records import MAX_MAGNITUDE, derived_diameters, normal_module

NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d{1,3})?")
INTEGER_MAX = 2_147_483_647  # PostgreSQL integer


class GearImportError(EngineError):
    """A gear file with bad rows. `problems` holds one line per problem, in file order."""

    def __init__(self, path: Any, problems: list[str], bad_rows: int) -> None:
        super().__init__(f"{path}: {bad_rows} bad row(s); nothing imported")
        self.problems = problems
        self.bad_rows = bad_rows


class CellError(ValueError):
    """A cell that cannot be read; the message is what is wrong with it ("is not a number")."""


# --- cell parsers: text → value, or CellError ---------------------------------------------

def parse_text(cell: str) -> str:
    return cell


def parse_number(cell: str) -> Decimal:
    if not NUMBER.fullmatch(cell):
        raise CellError("is not a number")
    value = Decimal(cell)
    if abs(value) > MAX_MAGNITUDE:
        raise CellError(f"is larger than {MAX_MAGNITUDE:g} in size (no quantity of a gear or hob is that large)")
    return value


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


def parse_hand(cell: str) -> str:
    if cell.upper() not in ("L", "R"):
        raise CellError("must be L or R")
    return cell.upper()


def parse_module_kind(cell: str) -> str:
    if cell.lower() not in MODULE_KINDS:
        raise CellError("must be normal or axial (a worm wheel's module as the worm's axial module)")
    return cell.lower()


def parse_class_name(cell: str) -> str:
    """Class names are lower case (`Spur` is spur); one that is not a safe class name
    (engine/names.py) is refused, as it would be printed in the program's comments."""
    name = cell.lower()
    if not is_safe("class", name):
        raise CellError(f"is not a gear class name: use {NAME_RULES['class'].rule}")
    return name


# --- the columns of design notes §9 ------------------------------------------------------

@dataclass(frozen=True)
class Column:
    """One gear CSV column: how to read a cell, whether every row must give it, and what a
    given value must satisfy (`check`, said as `rule` after the value)."""

    name: str
    parse: Callable[[str], Any]
    required: bool = False
    check: Callable[[Any], bool] | None = None
    rule: str = ""
    db_name: str | None = None

    @property
    def column(self) -> str:
        return self.db_name or self.name


POSITIVE = dict(check=lambda value: value > 0, rule="must be greater than 0")

COLUMNS: tuple[Column, ...] = (
    Column("gear_id", parse_positive_whole, required=True, db_name="id"),
    Column("gear_class", parse_class_name),
    Column("module", parse_number, required=True, **POSITIVE),
    Column("teeth", parse_positive_whole, required=True),
    Column("pressure_angle", parse_number, check=lambda v: 0 < v < 45, rule="is outside (0, 45)"),
    Column("helix_angle", parse_number, check=lambda v: 0 <= v < 60, rule="is outside [0, 60)"),
    Column("hand", parse_hand),
    Column("face_width", parse_number, required=True, **POSITIVE),
    Column("tip_diameter", parse_number, **POSITIVE),
    Column("root_diameter", parse_number, **POSITIVE),
    Column("cone_angle", parse_number, check=lambda v: -45 < v < 45, rule="is outside (-45, 45)"),
    Column("crowning", parse_number, check=lambda v: 0 <= v < 1, rule="is outside [0, 1) mm"),
    Column("material", parse_text),
    Column("hardness", parse_number, check=lambda v: 0 < v <= 700, rule="is outside (0, 700] HB (Brinell ends at 650)"),
    Column("quality_grade", parse_whole, check=lambda v: 1 <= v <= 12, rule="is outside 1..12"),
    Column("quantity", parse_positive_whole),
    Column("module_kind", parse_module_kind),
)
COLUMN_BY_NAME = {column.name: column for column in COLUMNS}
DEFAULTS = {"pressure_angle": Decimal(20), "helix_angle": Decimal(0)}


# --- reading the file --------------------------------------------------------------------

Record = tuple[int, list[str]]  # (physical line the record starts on, its cells)


def read_records(path: Path) -> list[Record]:
    """Every non-blank CSV record of the file with the line it starts on, cells stripped. No
    cell of these files holds a line break, so a record over several lines is a quote left
    open: refused at the line where it opens, before it swallows the rows after it."""
    records: list[Record] = []
    start = 1
    try:
        with open(path, encoding="utf-8-sig", newline="") as handle:
            reader = csv.reader(handle, strict=True)
            for record in reader:
                if reader.line_num > start:
                    raise EngineError(f"{path}: line {start}: a quote opened on this line is closed only on line "
                                      f"{reader.line_num}; close it on line {start} (a cell holds no line break)")
                cells = [cell.strip() for cell in record]
                if any(cells):
                    records.append((start, cells))
                start = reader.line_num + 1
    except FileNotFoundError:
        raise EngineError(f"{path}: no such file") from None
    except UnicodeDecodeError as error:
        raise EngineError(f"{path}: not UTF-8 text (byte at offset {error.start})") from None
    except OSError as error:
        raise EngineError(f"{path}: cannot read it ({error.strerror or error})") from None
    except csv.Error as error:
        raise EngineError(f"{path}: line {start}: {csv_problem(error)}") from None
    return records


def _header_names(path: Path, header: list[str]) -> list[str]:
    """The column name of each header cell ('' for a cell without a name), checked."""
    names = [cell.lower() for cell in header]
    unknown = [name for name in names if name and name not in COLUMN_BY_NAME]
    twice = sorted({name for name in names if name and names.count(name) > 1})
    missing = [column.name for column in COLUMNS if column.required and column.name not in names]
    problems = []
    if unknown:
        problems.append(f"unknown column(s) {', '.join(unknown)} "
                        f"(known: {', '.join(COLUMN_BY_NAME)})")
    if twice:
        problems.append(f"column(s) named twice: {', '.join(twice)}")
    if missing:
        problems.append(f"missing required column(s) {', '.join(missing)}")
    if problems:
        raise EngineError(f"{path}: " + "; ".join(problems))
    return names


# --- one row -----------------------------------------------------------------------------

def _cells_by_name(names: list[str], cells: list[str]) -> tuple[dict[str, str], list[str]]:
    """The row's cells by column name, and a problem for values outside the named columns."""
    by_name = {name: cell for name, cell in zip(names, cells) if name}
    stray = [cell for position, cell in enumerate(cells)
             if cell and (position >= len(names) or not names[position])]
    problems = [f"value(s) {', '.join(map(repr, stray))} outside the named columns"] if stray else []
    return by_name, problems


def _parse_cell(column: Column, cell: str) -> tuple[Any, str | None]:
    """(value, problem) of one cell; value None when the cell is empty (not given)."""
    if not cell:
        return None, (f"{column.name} is missing" if column.required else None)
    try:
        value = column.parse(cell)
    except CellError as error:
        return None, f"{column.name} {shown(cell)} {error}"
    if column.check is not None and not column.check(value):
        return value, f"{column.name} {cell} {column.rule}"
    return value, None


def _parse_row(names: list[str], cells: list[str]) -> tuple[dict[str, Any], list[str], set[str]]:
    """The gear of one record (every column, None where not given), its cell problems and
    the names of the columns whose cells are bad."""
    by_name, problems = _cells_by_name(names, cells)
    gear: dict[str, Any] = {}
    bad: set[str] = set()
    for column in COLUMNS:
        gear[column.name], problem = _parse_cell(column, by_name.get(column.name, ""))
        if problem:
            problems.append(problem)
            bad.add(column.name)
    return gear, problems, bad


# --- cross-column checks and completion of a parsed gear ---------------------------------
# Each step gets the gear and the installed classes {name: has a template}, may
# fill in what was not given, and returns a problem or None.

def _apply_defaults(gear: dict[str, Any], classes: dict[str, bool]) -> str | None:
    for name, default in DEFAULTS.items():
        if gear[name] is None:
            gear[name] = default
    return None


def _leaf_list(classes: dict[str, bool]) -> str:
    return ", ".join(sorted(name for name, has_template in classes.items() if has_template))


def _check_given_class(gear: dict[str, Any], classes: dict[str, bool]) -> str | None:
    """A class named in the file must be installed and have template rows (own or inherited);
    inner nodes of the tree have none."""
    given = gear["gear_class"]
    if given is None or classes.get(given):
        return None
    if given not in classes:
        return f"gear class '{given}' does not exist; known leaf classes: {_leaf_list(classes)}"
    return (f"gear class '{given}' is not a leaf class (an inner node of the tree, without template "
            f"rows); known leaf classes: {_leaf_list(classes)}")


def _classify(gear: dict[str, Any], classes: dict[str, bool]) -> str | None:
    """A gear without a class gets the one `classify` finds, which must be installed."""
    if gear["gear_class"] is not None:
        return None
    classification = classify(gear)
    if classification.gear_class is None:
        named = f"gear {gear['gear_id']} " if classification.remedy != Classification.remedy else ""
        return f"{named}{classification.problem}; {classification.remedy}"
    found = classification.gear_class
    gear["gear_class"] = found
    return None if classes.get(found) else not_installed_message(gear["gear_id"], found)


def _check_hand(gear: dict[str, Any], classes: dict[str, bool]) -> str | None:
    if gear["helix_angle"] != 0 and gear["hand"] is None:
        return f"hand is missing; a helical gear (helix_angle {gear['helix_angle']}) needs L or R"
    return None


def _fill_diameters(gear: dict[str, Any], classes: dict[str, bool]) -> str | None:
    """Compute tip and root diameters not given, from the normal module; root must stay positive
    and below tip."""
    module = normal_module(gear["module"], gear["module_kind"], gear["helix_angle"])
    tip, root = derived_diameters(module, gear["teeth"], gear["helix_angle"],
                                  gear["tip_diameter"], gear["root_diameter"])
    tip_said = "tip_diameter" if gear["tip_diameter"] is not None else "computed tip_diameter"
    root_said = "root_diameter" if gear["root_diameter"] is not None else "computed root_diameter"
    gear["tip_diameter"], gear["root_diameter"] = tip, root
    if root <= 0:
        return f"{root_said} {root:g} is not positive; give tip_diameter and root_diameter"
    if root >= tip:
        return f"{root_said} {root:g} is not smaller than {tip_said} {tip:g}"
    return None


# (columns a step reads, step): a step runs only when all the columns it reads are good,
# so a row reports every problem without repeating one.
COMPLETION_STEPS: tuple[tuple[tuple[str, ...], Callable[..., str | None]], ...] = (
    ((), _apply_defaults),
    (("gear_class",), _check_given_class),
    (("gear_id", "gear_class", "cone_angle", "crowning", "helix_angle", "material"), _classify),
    (("helix_angle", "hand"), _check_hand),
    (("gear_class", "module_kind"), _check_module_kind),
    (("module", "teeth", "helix_angle", "tip_diameter", "root_diameter", "module_kind"), _fill_diameters),
)


def _complete(gear: dict[str, Any], classes: dict[str, bool], bad: set[str]) -> list[str]:
    problems = (step(gear, classes) for reads, step in COMPLETION_STEPS if bad.isdisjoint(reads))
    return [problem for problem in problems if problem]


# --- the whole file ----------------------------------------------------------------------

def _duplicate_problems(gears: Iterable[tuple[int, dict[str, Any]]]) -> list[tuple[int, str]]:
    first_line: dict[int, int] = {}
    problems = []
    for line, gear in gears:
        gear_id = gear["gear_id"]
        if gear_id is None:
            continue
        if gear_id in first_line:
            problems.append((line, f"gear_id {gear_id} is already on line {first_line[gear_id]}"))
        else:
            first_line[gear_id] = line
    return problems


def _raise_problems(path: Path, problems: list[tuple[int, str]]) -> None:
    if problems:
        problems.sort(key=lambda problem: problem[0])  # stable: per line in column order
        lines = [f"line {line}: {text}" for line, text in problems]
        raise GearImportError(path, lines, len({line for line, _ in problems}))


def read_gears(path: str | Path, classes: dict[str, bool]) -> list[dict[str, Any]]:
    """Every gear of the CSV file at `path`, checked and completed (defaults, class,
    diameters), keyed by column name. `classes` maps each installed gear class to whether
    it has template rows (a class gears can be in). Raises GearImportError listing every problem, or EngineError."""
    path = Path(path)
    records = read_records(path)
    if len(records) < 2:
        raise EngineError(f"{path} has no gear rows")
    names = _header_names(path, records[0][1])
    parsed, problems = [], []
    for line, cells in records[1:]:
        gear, row_problems, bad_columns = _parse_row(names, cells)
        row_problems += _complete(gear, classes, bad_columns)
        problems.extend((line, problem) for problem in row_problems)
        parsed.append((line, gear))
    problems.extend(_duplicate_problems(parsed))
    _raise_problems(path, problems)
    return [gear for _, gear in parsed]


# --- storing -----------------------------------------------------------------------------

def installed_classes(conn: psycopg.Connection) -> dict[str, bool]:
    """{gear class name: whether it has template rows, its own or inherited}: the classes a
    gear can be in (leaves, and unit classes that others derive from, like spur)."""
    rows = conn.execute(
        "SELECT g.name, EXISTS (SELECT 1 FROM class_template(g.name)) FROM gear_class g").fetchall()
    return {name: has_template for name, has_template in rows}


_COLUMN_LIST = sql.SQL(", ").join(sql.Identifier(column.column) for column in COLUMNS)
_COPY = sql.SQL("COPY gear_import ({}) FROM STDIN").format(_COLUMN_LIST)
_UPSERT = sql.SQL(
    "INSERT INTO gear ({columns}) SELECT {columns} FROM gear_import "
    "ON CONFLICT (id) DO UPDATE SET {updates}").format(
    columns=_COLUMN_LIST,
    updates=sql.SQL(", ").join(
        sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(column.column))
        for column in COLUMNS if column.column != "id"))


def _store(conn: psycopg.Connection, path: Path, gears: list[dict[str, Any]]) -> None:
    """Upsert all gears in one transaction: COPY into a temporary table, then one INSERT."""
    try:
        with conn.transaction():
            conn.execute("CREATE TEMPORARY TABLE gear_import (LIKE gear) ON COMMIT DROP")
            with conn.cursor().copy(_COPY) as copy:
                for gear in gears:
                    copy.write_row([gear[column.name] for column in COLUMNS])
            conn.execute(_UPSERT)
            conn.execute("DROP TABLE gear_import")
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        message = error.diag.message_primary or str(error)
        raise EngineError(f"{path}: the database refused the gears ({message}); "
                          "nothing imported") from error


def import_gears(conn: psycopg.Connection, path: str | Path) -> int:
    """Import (insert or update by gear_id) every gear of the CSV file at `path`, all or
    nothing; return how many gears were imported or updated."""
    path = Path(path)
    gears = read_gears(path, installed_classes(conn))
    _store(conn, path, gears)
    return len(gears)
