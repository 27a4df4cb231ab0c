"""Workpieces from a gear CSV (design notes §9 columns).

The file is read by the one CSV reader (engine.csv_reader: `,` or `;` with decimal commas). Every
row is read and checked first (cells, class, module kind, the diameters of cylindrical gears against
m_n, z, β and x); only when the whole file is good are all its gears stored, in one transaction. A
file with any bad row stores nothing and reports every problem, one line each, as
`<file>, line N, column C: what; what to do`. A gear_id already stored is refused unless `replace`,
which reports every changed field. Numbers are kept as Decimal, so they are stored exactly as written.
"""
from __future__ import annotations

from collections.abc import Callable, Iterable
from decimal import Decimal
from pathlib import Path
from typing import Any

import msgspec

from ..csv_reader import (
    CellError,
    Column,
    CsvError,
    CsvFile,
    CsvKind,
    Problem,
    declare,
    parse_number,
    parse_positive_whole,
    parse_text,
    parse_whole,
    read_csv_file,
)
from ..errors import EngineError
from ..names import NAME_RULES, is_safe
from .classify import NAME_THE_CLASS, classify, not_installed_message
from .gear_geometry import diameter_problems, tip_from_shift
from .module_kind import MODULE_KINDS
from .module_kind import check_module_kind as _check_module_kind
from .records import derived_diameters, normal_module

__all__ = ["CellError", "Column", "GearImportError", "derived_diameters", "read_gears"]


GearImportError = CsvError   # a file of bad rows: `problems` holds one line per problem, in file order


# --- cell parsers of the gear columns: text → value, or CellError --------------------------

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


declare(parse_hand, "hand", "write L or R (the helix hand)")
declare(parse_module_kind, "module kind", "write normal or axial")
declare(parse_class_name, "gear class", "write the name of a leaf class (engine template list), or leave it empty")


# --- the columns of design notes §9 ------------------------------------------------------

POSITIVE: dict[str, Any] = dict(check=lambda value: value > 0, rule="must be greater than 0")

COLUMNS: tuple[Column, ...] = (
    Column("gear_id", parse_positive_whole, required=True, db_name="id"),
    Column("gear_class", parse_class_name),
    Column("module", parse_number, required=True, unit="mm", **POSITIVE),
    Column("teeth", parse_positive_whole, required=True),
    Column("pressure_angle", parse_number, check=lambda v: 0 < v < 45, rule="is outside (0, 45)", unit="degrees"),
    Column("helix_angle", parse_number, check=lambda v: 0 <= v < 60, rule="is outside [0, 60)", unit="degrees"),
    Column("hand", parse_hand),
    Column("face_width", parse_number, required=True, unit="mm", **POSITIVE),
    Column("tip_diameter", parse_number, unit="mm", **POSITIVE),
    Column("root_diameter", parse_number, unit="mm", **POSITIVE),
    Column("cone_angle", parse_number, check=lambda v: -45 < v < 45, rule="is outside (-45, 45)", unit="degrees"),
    Column("crowning", parse_number, check=lambda v: 0 <= v < 1, rule="is outside [0, 1) mm", unit="mm"),
    Column("material", parse_text),
    Column("hardness", parse_number, check=lambda v: 0 < v <= 700, rule="is outside (0, 700] HB (Brinell ends at 650)",
           unit="HB"),
    Column("quality_grade", parse_whole, check=lambda v: 1 <= v <= 12, rule="is outside 1..12"),
    Column("quantity", parse_positive_whole),
    Column("module_kind", parse_module_kind),
    Column("profile_shift", parse_number, check=lambda v: -2 < v < 2, rule="is outside (-2, 2)", unit="modules"),
)
GEAR_KIND = CsvKind("gear", COLUMNS)
DEFAULTS = {"pressure_angle": Decimal(20), "helix_angle": Decimal(0)}


# --- one row -----------------------------------------------------------------------------

def _stray_problems(names: list[str], cells: list[str], line: int) -> list[Problem]:
    """Values under a header cell without a name would be lost: refused."""
    stray = [cell for name, cell in zip(names, cells) if cell and not name]
    return [Problem(line, None, f"value(s) {', '.join(map(repr, stray))} outside the named columns",
                    "name their column in the header, or delete them")] if stray else []


def _parse_row(file: CsvFile, line: int, cells: list[str]) -> tuple[dict[str, Any], list[Problem], set[str]]:
    """The gear of one record (every column, None where not given), its cell problems and
    the names of the columns whose cells are bad."""
    by_name = {name: cell for name, cell in zip(file.header, cells) if name}
    problems = _stray_problems(file.header, cells, line)
    gear: dict[str, Any] = {}
    bad: set[str] = set()
    for column in COLUMNS:
        gear[column.name], problem = file.cell(column, by_name.get(column.name, ""), line)
        if problem:
            problems.append(problem)
            bad.add(column.name)
    return gear, problems, bad


# --- cross-column checks and completion of a parsed gear ---------------------------------
# Each step gets the gear and the installed classes, may fill in what was not given, and
# returns a problem (column, what is wrong; what to do) or None.

Said = tuple[str, str] | None   # (column, "what is wrong; what to do")


class Classes(msgspec.Struct, frozen=True):
    """The installed gear classes {name: has template rows, own or inherited} (a class gears can be in),
    and those checked against the cylindrical-gear diameter formulas (engine.gears.gear_geometry)."""

    templated: dict[str, bool]
    cylindrical: frozenset[str] = msgspec.field(default_factory=frozenset)


def _apply_defaults(gear: dict[str, Any], classes: Classes) -> Said:
    for name, default in DEFAULTS.items():
        if gear[name] is None:
            gear[name] = default
    return None


def _leaf_list(classes: Classes) -> str:
    return ", ".join(sorted(name for name, has_template in classes.templated.items() if has_template))


def _check_given_class(gear: dict[str, Any], classes: Classes) -> Said:
    """A class named in the file must be installed and have template rows (own or inherited);
    inner nodes of the tree have none."""
    given = gear["gear_class"]
    if given is None or classes.templated.get(given):
        return None
    if given not in classes.templated:
        return "gear_class", f"gear class '{given}' does not exist; known leaf classes: {_leaf_list(classes)}"
    return "gear_class", (f"gear class '{given}' is not a leaf class (an inner node of the tree, without template "
                          f"rows); known leaf classes: {_leaf_list(classes)}")


# Key of a read gear whose class the tree gave (the file named none): a stored gear's units, which
# the gear file has no column for, are counted in again when it replaces that gear (gear_store).
FROM_TREE = "class_from_tree"


def _classify(gear: dict[str, Any], classes: Classes) -> Said:
    """A gear without a class gets the one `classify` finds, which must be installed."""
    if gear["gear_class"] is not None:
        return None
    classification = classify(gear)
    if classification.gear_class is None:
        named = f"gear {gear['gear_id']} " if classification.remedy != NAME_THE_CLASS else ""
        return "gear_class", f"{named}{classification.problem}; {classification.remedy}"
    found = classification.gear_class
    gear["gear_class"], gear[FROM_TREE] = found, True
    return None if classes.templated.get(found) else ("gear_class", not_installed_message(gear["gear_id"], found))


def _check_hand(gear: dict[str, Any], classes: Classes) -> Said:
    if gear["helix_angle"] != 0 and gear["hand"] is None:
        return "hand", f"is missing; a helical gear (helix_angle {gear['helix_angle']}) needs L or R"
    return None


def _check_kind(gear: dict[str, Any], classes: Classes) -> Said:
    problem = _check_module_kind(gear, classes.templated)
    return ("module_kind", problem.removeprefix("module_kind ")) if problem else None


def _fill_diameters(gear: dict[str, Any], classes: Classes) -> Said:
    """Compute tip and root diameters not given, from the normal module (and the profile shift when
    given); root must stay positive and below tip."""
    module = normal_module(gear["module"], gear["module_kind"], gear["helix_angle"])
    tip = gear["tip_diameter"]
    if tip is None and gear["profile_shift"] is not None:
        tip = Decimal(repr(round(tip_from_shift(gear, float(gear["profile_shift"])), 4)))
    tip, root = derived_diameters(module, gear["teeth"], gear["helix_angle"], tip, gear["root_diameter"])
    tip_said = "tip_diameter" if gear["tip_diameter"] is not None else "computed tip_diameter"
    root_said = "root_diameter" if gear["root_diameter"] is not None else "computed root_diameter"
    gear["tip_diameter"], gear["root_diameter"] = tip, root
    if root <= 0:
        return "root_diameter", f"{root_said} {root:g} is not positive; give tip_diameter and root_diameter"
    if root >= tip:
        return "root_diameter", f"{root_said} {root:g} is not smaller than {tip_said} {tip:g}"
    return None


def _check_geometry(gear: dict[str, Any], classes: Classes) -> list[Problem] | None:
    """Given diameters of a cylindrical gear against m_n, z, β and x (engine.gears.gear_geometry)."""
    return diameter_problems(gear) if gear["gear_class"] in classes.cylindrical else None


# (columns a step reads, step): a step runs only when all the columns it reads are good,
# so a row reports every problem without repeating one.
COMPLETION_STEPS: tuple[tuple[tuple[str, ...], Callable[..., Any]], ...] = (
    ((), _apply_defaults),
    (("gear_class",), _check_given_class),
    (("gear_id", "gear_class", "cone_angle", "crowning", "helix_angle", "material"), _classify),
    (("helix_angle", "hand"), _check_hand),
    (("gear_class", "module_kind"), _check_kind),
    (("gear_class", "module", "teeth", "helix_angle", "tip_diameter", "root_diameter", "module_kind",
      "profile_shift"), _check_geometry),
    (("module", "teeth", "helix_angle", "tip_diameter", "root_diameter", "module_kind", "profile_shift"),
     _fill_diameters),
)


def _as_problems(line: int, found: Any) -> list[Problem]:
    """A step's finding as Problems of the line: a Said, or Problems of their own."""
    if not found:
        return []
    if isinstance(found, list):
        return [Problem(line, problem.column, problem.what, problem.todo) for problem in found]
    column, text = found
    what, _, todo = text.partition("; ")
    return [Problem(line, column, what, todo)]


def _complete(gear: dict[str, Any], classes: Classes, bad: set[str], line: int) -> list[Problem]:
    """The steps in order; a column a step found bad is not read by the steps after it."""
    problems: list[Problem] = []
    for reads, step in COMPLETION_STEPS:
        if bad.isdisjoint(reads):
            found = _as_problems(line, step(gear, classes))
            bad = bad | {problem.column for problem in found if problem.column is not None}
            problems += found
    return problems


# --- the whole file ----------------------------------------------------------------------

def _duplicate_problems(gears: Iterable[tuple[int, dict[str, Any]]]) -> list[Problem]:
    first_line: dict[int, int] = {}
    problems = []
    for line, gear in gears:
        gear_id = gear["gear_id"]
        if gear_id is None:
            continue
        if gear_id in first_line:
            problems.append(Problem(line, "gear_id", f"{gear_id} is already on line {first_line[gear_id]}",
                                    "give each gear once"))
        else:
            first_line[gear_id] = line
    return problems


def read_gears(path: str | Path, classes: Classes | dict[str, bool]) -> list[dict[str, Any]]:
    """Every gear of the CSV file at `path`, checked and completed (defaults, class,
    diameters), keyed by column name, each with its `line`. `classes`: the installed classes
    (a bare {name: has template rows} checks no geometry). Raises GearImportError listing every
    problem, or EngineError."""
    classes = classes if isinstance(classes, Classes) else Classes(classes)
    file = read_csv_file(path, GEAR_KIND)
    if not file.records:
        raise EngineError(f"{path} has no gear rows; give one gear per line under the header")
    parsed, problems = [], []
    for line, cells in file.records:
        gear, row_problems, bad_columns = _parse_row(file, line, cells)
        problems += row_problems + _complete(gear, classes, bad_columns, line)
        parsed.append((line, gear))
    problems.extend(_duplicate_problems(parsed))
    if problems:
        raise GearImportError(path, problems)
    return [gear | {"line": line} for line, gear in parsed]
