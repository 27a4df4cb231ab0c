"""Adding machine records from a CSV file (`engine machines import`): the columns of the machine
table, as `engine machines list --csv` writes them and seed_templates/machines.csv holds them;
name, kind, dialect, the travel (x_min … z_max) and spindle_max are required (REQUIRED), an empty
cell takes the column's default. A shop adds its own lathe or hobber here instead of in SQL.

Only new machines are added, unless --replace: then a stored machine of the file is replaced
whole (an empty cell its column's default), each changed field said old → new. A machine stored
jobs were made on is the one their programs were proved against, so --replace changes it in no
field (engine.db.replacing): the file exported and imported again passes, a changed travel or
control fact is a deliberate edit in SQL or a machine of a new name
(docs/guide/machines-and-simulation.md). A kind and dialect the verifier has no
grammar for is refused where it enters, naming the ones it has: such a machine could never be
given a program. All or nothing: any bad row stops the file, nothing stored."""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
import psycopg
from psycopg import sql

from ..csv_reader import Column, CsvKind, parse_text, read_csv_file
from ..db.connection import scalar
from ..db.listing import exact_records
from ..db.replacing import Change, changed_fields, jobs_of, plain, refuse_held
from ..errors import EngineError
from ..names import shown
from .records import FLOOR_TIMES, Machine

if TYPE_CHECKING:
    from ..db.connection import Connection

# The columns a machine cannot do without (NOT NULL, no default): the rest take their default.
REQUIRED = ("name", "kind", "dialect", "x_min", "x_max", "z_min", "z_max", "spindle_max")
# The columns of the machine table (the record's fields), as text the database converts.
MACHINE_KIND = CsvKind("machine", tuple(Column(name, parse_text, required=name in REQUIRED)
                                        for name in Machine.__struct_fields__))
NUMBERS = tuple(name for name in Machine.__struct_fields__
                if Machine.__annotations__[name].split(" ")[0] in ("float", "int"))   # the annotations are text
# What each of the table's checks asks, in the words of the record's columns (schema/schema.sql).
CHECKS = {
    "machine_kind_check": "kind must be hobber or lathe",
    "machine_check": "x_min must be below x_max, y_min at most y_max and z_min below z_max (mm)",
    "machine_spindle_max_check": "spindle_max must be above 0 (r/min)",
    "machine_work_offset_check": "work_offset must be one of G54, G55, G56, G57",
    "machine_gcode_system_check": "gcode_system must be A, B or C (empty: none stated)",
    "machine_decimal_point_input_check": "decimal_point_input must be increment or calculator",
    "machine_power_on_check": "power_on lists modal codes among G18 G40 G90 G94 G95 G97 G98 G99, one space "
                              "apart (never G20/G21: the program states its units)",
    "machine_reference_point": "reference_x and reference_z are given together or not at all",
    "machine_load_position": "load_x and load_z are given together or not at all",
    "machine_safe_name": "a machine name is letters, digits, - and _ (it is printed in programs' comments)",
    "machine_rapid_rate_check": "rapid_rate must be above 0 (mm/min)",
    **{f"machine_{axis}_direction_check": f"{axis}_direction must be 1 or -1 (its sense against DIN 66217)"
       for axis in "abcyz"},
    **{f"machine_{column}_check": f"{column} must be 0 or more (mm)"
       for column in ("fixture_diameter", "fixture_gap", "tailstock_diameter", "tailstock_gap")},
    **{f"machine_door_{which}_m_check": f"door_{which}_m must be an M number from 0 to 999"
       for which in ("close", "open")},
    "machine_egb_helix_sign_check": "egb_helix_sign must be 1 or -1 (the sign of the Fanuc helical compensation, "
                                    "fanuc-egb.md §F5; empty: not stated)",
    "machine_program_number_base_check": "program_number_base must be a whole number from 0 to 99998 (a Fanuc "
                                         "program's O number is it plus the gear's id; empty: none stated)",
    "machine_swivel_speed_check": "swivel_speed must be above 0 (degrees per second)",
    **{f"machine_{column}_check": f"{column} must be 0 or more (seconds)"
       for column in ("spindle_runup", "coupling_sync", "tailstock_time", "door_time", "tool_change_time",
                      "load_unload_time")},
}


FIELDS = Machine.__struct_fields__
# the record as stored (numbers digit for digit): what --csv writes and --replace compares
EXPORT = sql.SQL("SELECT {} FROM machine ORDER BY name").format(sql.SQL(", ").join(map(sql.Identifier, FIELDS)))
LOCKED = sql.SQL("SELECT {} FROM machine WHERE name = ANY(%s) ORDER BY name FOR UPDATE").format(
    sql.SQL(", ").join(map(sql.Identifier, FIELDS)))
# a replaced machine is replaced whole: a column the row leaves empty takes its default (EXCLUDED's)
WHOLE = sql.SQL(", ").join(sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(name)) for name in FIELDS[1:])
ONE = sql.SQL("SELECT {} FROM machine WHERE name = %s").format(sql.SQL(", ").join(map(sql.Identifier, FIELDS)))
JOB_COUNT = "SELECT count(*)::int FROM job WHERE machine = %s"
JOBS_ON = "SELECT machine, array_agg(id ORDER BY id) FROM job WHERE machine = ANY(%s) GROUP BY machine"


def export_machines(conn: Connection) -> list[dict[str, Any]]:
    """Every machine record by name as `engine machines import` reads it (each value as stored)."""
    return exact_records(conn.execute(EXPORT))


def show_machine(conn: Connection, name: str) -> dict[str, Any]:
    """The machine of that name (as stored, numbers as JSON numbers) with the count of stored jobs
    made on it; EngineError naming the known machines when there is none."""
    found = exact_records(conn.execute(ONE, (name,)))
    if not found:
        known = ", ".join(row[0] for row in conn.execute("SELECT name FROM machine ORDER BY name"))
        raise EngineError(f"machine {shown(name)} does not exist; known machines: {known or 'none'} "
                          "(engine machines list)")
    record = {key: plain(value) for key, value in found[0].items()}
    return {**record, "job_count": scalar(conn.execute(JOB_COUNT, (name,)))}


def read_machines(path: str | Path) -> list[dict[str, Any]]:
    """The rows of a machines CSV as {column: text}, an empty cell None (the column's default);
    a row without one of the REQUIRED columns, or with text where a number goes, is refused,
    naming its line and the column."""
    machines = [_machine(path, line, row) for line, row in read_csv_file(path, MACHINE_KIND).rows()]
    if not machines:
        raise EngineError(f"{path} holds no machine, only its header; add a row per machine; nothing imported")
    return machines


def _machine(path, line: int, row: dict[str, str]) -> dict[str, Any]:
    machine = {key: (value if value != "" else None) for key, value in row.items()}
    missing = [column for column in REQUIRED if machine[column] is None]
    if missing:
        raise EngineError(f"{path}: line {line} gives no {missing[0]}; every machine needs "
                          f"{', '.join(REQUIRED)}; nothing imported")
    for column in NUMBERS:
        text = machine.get(column)
        if text is not None and not _is_number(text):
            raise EngineError(f"{path}: line {line} column {column}: {shown(text)} is not a number "
                              "(write 350.5 with a point, no unit); nothing imported")
    return machine


def _is_number(text: str) -> bool:
    try:
        return abs(float(text)) < float("inf")
    except ValueError:
        return False


def import_machines(conn: Connection, path: str | Path, grammars: set[tuple[str, str]],
                    fault: Callable[[dict], str | None] = lambda machine: None, *,
                    replace: bool = False) -> MachineImport:
    """Add every machine of the CSV file at `path`, all or nothing; `grammars`: the (kind, dialect)
    pairs the verifier reads; `fault(machine)`: why the verifier could never take the record as it
    is (a power-on state its control cannot be in), or None; `replace`: a stored machine of the
    file (its name as stored) is replaced whole, unless stored jobs were made on it and the file
    changes it."""
    machines = read_machines(path)
    for machine in machines:
        _refuse_unknown_grammar(path, machine, grammars)
        _refuse_reference_outside(path, machine)
        if (why := fault(machine)) is not None:
            raise EngineError(f"{path}: machine {shown(machine['name'])}: {why}; correct the row; nothing imported")
    names = [machine["name"] for machine in machines]
    _refuse_repeated(path, names)
    with conn.transaction():
        stored = {row["name"]: row for row in exact_records(conn.execute(LOCKED, (names,)))}
        _refuse_existing(conn, path, [name for name in names if not (replace and name in stored)])
        for machine in machines:
            _insert(conn, path, machine)
        changes = changed_fields(stored, exact_records(conn.execute(LOCKED, (list(stored),))), "name", FIELDS[1:])
        refuse_held(path, "machine", changes, jobs_of(conn, JOBS_ON, [change.key for change in changes]),
                    relation="{jobs} {were} made on it")
    return MachineImport([name for name in names if name not in stored], list(stored), changes)


class MachineImport(msgspec.Struct, frozen=True):
    """What an import did: the machines added, those replaced (by name) and their changed fields."""

    added: list[str]
    replaced: list[str]
    changes: list[Change]


def _refuse_unknown_grammar(path, machine: dict, grammars: set[tuple[str, str]]) -> None:
    if (machine["kind"], machine["dialect"]) not in grammars:
        known = ", ".join(f"{kind} {dialect}" for kind, dialect in sorted(grammars))
        raise EngineError(f"{path}: machine {shown(machine['name'])} is a {shown(machine['kind'])} of dialect "
                          f"{shown(machine['dialect'])}, which no grammar of the verifier reads; use one of: "
                          f"{known}; nothing imported")


def _refuse_reference_outside(path, machine: dict) -> None:
    """The reference point (G28's, an ISO lathe's) lies within the machine's own travel: a point
    outside it would refuse every program that returns there, as a move beyond the travel."""
    for axis in ("x", "z"):
        point = machine.get(f"reference_{axis}")
        low, high = float(machine[f"{axis}_min"]), float(machine[f"{axis}_max"])
        if point is not None and not low <= float(point) <= high:
            raise EngineError(f"{path}: machine {shown(machine['name'])}: reference_{axis} {point} lies outside its "
                              f"travel ({axis.upper()} {machine[f'{axis}_min']}…{machine[f'{axis}_max']}); "
                              "give the point the control's parameters hold; nothing imported")


def _refuse_repeated(path, names: list[str]) -> None:
    """A name given twice, also in another case: `--machine` finds a machine by its name as typed,
    and two names an operator cannot tell apart would pick the wrong record."""
    folded = [name.casefold() for name in names]
    repeated = sorted({name for name, fold in zip(names, folded) if folded.count(fold) > 1})
    if repeated:
        raise EngineError(f"{path}: machine {shown(repeated[0])} is given twice (names that differ only in case "
                          "are one machine); give each machine once; nothing imported")


def _refuse_existing(conn: Connection, path, names: list[str]) -> None:
    found = [name for (name,) in conn.execute(
        "SELECT name FROM machine WHERE lower(name) = ANY(%s) ORDER BY name", ([name.lower() for name in names],))]
    if found:
        raise EngineError(f"{path}: machine(s) {', '.join(found)} exist already (names that differ only in case "
                          "are one machine): without --replace an import adds new machines only; remove their rows "
                          "from the file, give a new machine another name, or replace the records as stored "
                          "(--replace, the name as listed); nothing imported")


def _insert(conn: Connection, path, machine: dict) -> None:
    """One record; a value the table's checks refuse (a negative spindle limit) names the machine
    and what the check asks, inside the file's transaction (nothing of the file is stored)."""
    given = {column: value for column, value in machine.items() if value is not None}   # empty: the default
    try:
        conn.execute(sql.SQL("INSERT INTO machine ({}) VALUES ({}) ON CONFLICT (name) DO UPDATE SET {}").format(
            sql.SQL(", ").join(map(sql.Identifier, given)), sql.SQL(", ").join(sql.Placeholder() * len(given)),
            WHOLE), list(given.values()))
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        asks = CHECKS.get(error.diag.constraint_name or "", error.diag.message_primary or str(error))
        raise EngineError(f"{path}: machine {shown(machine['name'])}: {asks}; nothing imported") from error


def partial_floor_time_notes(path: str | Path) -> list[str]:
    """A note per hobber of the file that states some of its FLOOR_TIMES but not all: its programs
    print no `; FLOOR TO FLOOR` line until it states the rest (a record stating none is the
    machine that keeps no such times, said nowhere; engine machines list shows both)."""
    notes = []
    for machine in read_machines(path):
        missing = [name for name in FLOOR_TIMES if machine.get(name) is None]
        if machine["kind"] == "hobber" and 0 < len(missing) < len(FLOOR_TIMES):
            notes.append(f"machine {machine['name']} states some floor-to-floor times but not {', '.join(missing)}: "
                         "its programs have no FLOOR TO FLOOR line until it states them (in SQL)")
    return notes
