"""A golden test made from a proven stored program (`engine test add --from-program ID`, issue 31).

A shop has no golden tests of its own classes; the programs it has proved at the machine are its
best statement of what a template must make. The test is a params test (template_test.params):
the program's job parameters and module parameters on its machine, so it runs the class's rows
exactly as they ran for that job, whatever the hob choice or the models do later. Its
expectations are the program's lines (`line N: …`, the lineage line left out as every test's
program is, and the lines that show the template's version, which every new draft changes) and
its numeric properties (line count, G0/G1 blocks, the range of each axis, the EGON ratio), each
with the tolerance of the number as the program printed it.

Only a program the verifier and the simulation proved is taken (a program stored --unverified is
refused), and only one the class's current rows still make: the test is run once before it is
stored, so a test that would fail on the day it is added is refused, naming the first difference."""
from __future__ import annotations

import math
import re
from typing import TYPE_CHECKING

import msgspec
from psycopg.errors import InsufficientPrivilege
from psycopg.types.json import Jsonb

from ..errors import EngineError
from ..names import shown
from ..templates.program_properties import read_property
from .golden import run_golden_test
from .golden_runs import MODULE_PARAMS_KEY, GoldenTest

if TYPE_CHECKING:
    from ..db.connection import Connection

PROGRAM = ("SELECT p.id, p.gear_class, p.template_version, p.lines, p.row_ids, p.unverified, p.trace, "
           "j.machine, j.params, j.module_params FROM program p JOIN job j ON j.id = p.job_id WHERE p.id = %s")
INSERT = ("INSERT INTO template_test (gear_class, name, params, choices, expect, description) "
          "VALUES (%s, %s, %s, %s, %s, %s) RETURNING id")
TAKEN = "SELECT 1 FROM template_test WHERE gear_class = %s AND name = %s"
LINEAGE_ROW = -1                  # the lineage line's row id: not part of a test's program
VERSION_ORIGIN = "template"       # an input of this origin (trace) is the template's own version
AXES = ("X", "Y", "Z", "A", "B", "C")   # positioning addresses whose range a test states
COUNTED = ("G0", "G1")                  # motion words whose blocks a test counts
EDITOR_ROLE = "engine_editor"


class StoredProgram(msgspec.Struct, frozen=True):
    id: int
    gear_class: str
    version: int
    lines: list[str]
    row_ids: list[int]
    unverified: bool
    trace: dict | None
    machine: str
    params: dict
    module_params: dict


class AddedTest(msgspec.Struct, frozen=True):
    id: int
    gear_class: str
    name: str
    expectations: int
    left_out: int       # lines showing the template's version, not stated


def add_from_program(conn: Connection, program_id: int, name: str | None = None) -> AddedTest:
    """Store the golden test of a proven program; EngineError in one line, nothing stored, if the
    program is not found, not proved, or not what the class's rows make now."""
    program = _load(conn, program_id)
    name = _checked_name(f"program{program.id}" if name is None else name)
    if conn.execute(TAKEN, (program.gear_class, name)).fetchone():
        raise EngineError(f"class {program.gear_class} has a golden test named {name} already; give another --name")
    expect, left_out = expectations(program)
    test = GoldenTest(0, program.gear_class, name, None, _params(program), {"machine": program.machine},
                      tuple(expect), f"from program {program.id} ({program.gear_class} v{program.version})")
    _refuse_failing(conn, test, program)
    return AddedTest(_insert(conn, test), program.gear_class, name, len(expect), left_out)


# template_test.name's CHECK (schema/schema.sql): a name the table would refuse is refused first,
# in one line (it met the CHECK and ended as an unexpected error, exit 2)
TEST_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,79}")
TEST_NAME_RULE = "letters, digits, _, - and ., starting with a letter or digit, at most 80 characters"


def _checked_name(name: str) -> str:
    if not TEST_NAME.fullmatch(name):
        raise EngineError(f"golden test name {shown(name)} is not a safe golden test name: use {TEST_NAME_RULE}; "
                          "give another --name")
    return name


def _load(conn: Connection, program_id: int) -> StoredProgram:
    row = conn.execute(PROGRAM, (program_id,)).fetchone()
    if row is None:
        raise EngineError(f"program {program_id} does not exist; see engine programs list")
    program = StoredProgram(*row)
    if program.unverified:
        raise EngineError(f"program {program_id} is stored unverified (no verifier proved it): only a program "
                          "proved by the verifier and the simulation makes a golden test")
    return program


def _params(program: StoredProgram) -> dict:
    """The job's parameters as a params test gives them (engine.release.golden_runs)."""
    return {**program.params, MODULE_PARAMS_KEY: program.module_params} if program.module_params \
        else dict(program.params)


def expectations(program: StoredProgram) -> tuple[list[str], int]:
    """(the program's lines and numeric properties as expectations, lines left out)."""
    lines = [line for line, row in zip(program.lines, program.row_ids) if row != LINEAGE_ROW]
    rows = [row for row in program.row_ids if row != LINEAGE_ROW]
    versioned = version_rows(program.trace)
    stated = [f"line {number}: {line}" for number, (line, row) in enumerate(zip(lines, rows), 1)
              if row not in versioned]
    return stated + properties(lines), len(lines) - len(stated)


def version_rows(trace: dict | None) -> set[int]:
    """Rows whose line reads the template's version, directly or through a row that computed a
    value from it (the trace names each input's origin: `template`, `row N`, `job`, `module …`)."""
    found: set[int] = set()
    for entry in (trace or {}).get("rows", ()):
        origins = [origin for column in (entry.get("read") or {}).values() for origin in column.values()]
        if any(origin == VERSION_ORIGIN or _row_of(origin) in found for origin in origins):
            found.add(entry["row"])
    return found


def _row_of(origin: str) -> int | None:
    head, _, number = origin.partition(" ")
    return int(number) if head == "row" and number.lstrip("-").isdigit() else None


def properties(lines: list[str]) -> list[str]:
    """The numeric properties the program has, each as the program printed it."""
    names = ["line count", *(f"count of {word}" for word in COUNTED),
             *(f"{pick} {axis}" for axis in AXES for pick in ("min", "max")), "EGON ratio"]
    found = [(name, read_property(name, lines)) for name in names]
    return [f"{name} = {_printed(reading.value, reading.printed_step)}" for name, reading in found
            if reading is not None]


def _printed(value: float, step: float) -> str:
    """The value with the decimals the program printed it with (0 for a count)."""
    decimals = max(0, round(-math.log10(step))) if 0 < step < 1 else 0
    return f"{value:.{decimals}f}" if step else f"{value:g}"


def _refuse_failing(conn: Connection, test: GoldenTest, program: StoredProgram) -> None:
    """The test run once against the class's current rows (verifier and simulation included)."""
    result = run_golden_test(conn, test, draft=True)
    if not result.passed:
        failure = (result.failure or "").removeprefix(f"test {test.label}: ")
        raise EngineError(f"program {program.id} is not what class {program.gear_class}'s current rows "
                          f"(v{result.version}) make: {failure}; no test added")


def _insert(conn: Connection, test: GoldenTest) -> int:
    try:
        with conn.transaction():
            row = conn.execute(INSERT, (test.gear_class, test.name, Jsonb(test.params), Jsonb(test.choices),
                                        list(test.expect), test.description)).fetchone()
    except InsufficientPrivilege:
        raise EngineError(f"adding a golden test needs the role {EDITOR_ROLE} (nothing added)") from None
    assert row is not None   # INSERT … RETURNING gives its row
    return row[0]
