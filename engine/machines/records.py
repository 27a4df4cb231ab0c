"""Machines as read from the database: the record of one machine (its kind, NC dialect, axis
travel in mm, spindle and table limits, axis senses and setup) and loading it by name."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..db.records import as_float, columns
from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection


class Machine(msgspec.Struct, frozen=True):
    """A machine record (table machine): its kind and dialect, axis travels (mm), speed limits (r/min) and fixture
    sizes."""
    name: str
    kind: str
    dialect: str
    x_min: float
    x_max: float
    y_min: float
    y_max: float
    z_min: float
    z_max: float
    spindle_max: float
    table_speed_max: float | None
    module_max: float | None
    # Conventions and setup (the machine table): each axis's sense relative to DIN 66217.
    a_direction: int = 1
    b_direction: int = 1
    c_direction: int = 1
    y_direction: int = 1
    z_direction: int = 1
    work_offset: str = "G54"
    fixture_diameter: float = 0.0
    fixture_gap: float = 0.0
    tailstock_diameter: float = 0.0
    tailstock_gap: float = 0.0
    load_x: float | None = None
    load_z: float | None = None
    rapid_rate: float = 5000.0
    orient_before_coupling: bool = False
    door_close_m: int | None = None
    door_open_m: int | None = None
    # ISO lathes (issue 27, migration 0029): the G28 reference point in the travel's frame, and the
    # G-code system ('A': X/Z absolute, U/W incremental, G90 a cycle; 'B'/'C'/None: G90 absolute).
    reference_x: float | None = None
    reference_z: float | None = None
    gcode_system: str | None = None
    # How the control reads a dimension word without a decimal point (migration 0030): 'increment'
    # (X118 = 0.118 mm, refused) or 'calculator' (X118 = 118 mm; Fanuc parameter 3401#0 DPI = 1).
    decimal_point_input: str = "increment"
    # The modal G codes the control is in at power-on and reset ('G18 G21 G40 G97 G99'), which a
    # program that does not state them runs under; None: not stated (such a program is refused).
    power_on: str | None = None
    # What a hobbing program does besides cutting (migration 0034; None: not stated), for its
    # floor-to-floor time (engine.hobbing.floor_time): degrees per second of the swivel head, and
    # seconds of a spindle start, a coupling's synchronisation, a tailstock clamp or release, a door
    # close or open, a tool call, and loading and unloading one part.
    swivel_speed: float | None = None
    spindle_runup: float | None = None
    coupling_sync: float | None = None
    tailstock_time: float | None = None
    door_time: float | None = None
    tool_change_time: float | None = None
    load_unload_time: float | None = None
    # Fanuc hobbers (issue 30, migration 0037): the sign the control applies G81's helical
    # compensation Z·sin P·360/(π·T·Q) degrees of C per mm of Z with, in the machine's C and Z
    # senses (fanuc-egb.md §F4, §F5): +1 the literal formula, -1 its opposite; None: not stated
    # (the simulation refuses a helical gear's Fanuc program).
    egb_helix_sign: int | None = None
    # Fanuc hobbers (migration 0038): the O number of a gear's program is program_number_base + the
    # gear's id (engine.hobbing.dialects); None: no rule stated (no Fanuc hobbing program).
    program_number_base: int | None = None


# The times a hobber's record states for the floor-to-floor time, in this order (migration 0034).
FLOOR_TIMES = ("swivel_speed", "spindle_runup", "coupling_sync", "tailstock_time", "door_time", "tool_change_time",
               "load_unload_time")


def unstated_floor_times(machine: Machine) -> list[str]:
    """The FLOOR_TIMES the record leaves NULL (all stated: none; a floor-to-floor time needs all)."""
    return [name for name in FLOOR_TIMES if getattr(machine, name) is None]


def floor_times_said(kind: str, missing: list[str]) -> str:
    """Whether a machine's programs state `; FLOOR TO FLOOR`, for `engine machines list`: 'yes' (a
    hobber stating every FLOOR_TIMES), 'missing <names>' (some), 'none stated', '-' (a lathe: the
    floor-to-floor time is the hobbing cycle's, engine.hobbing.floor_time)."""
    if kind != "hobber":
        return "-"
    if not missing:
        return "yes"
    return "none stated" if len(missing) == len(FLOOR_TIMES) else f"missing {', '.join(missing)}"


MACHINE_QUERY = f"SELECT {columns(Machine)} FROM machine"  # static, from the record's fields


DEFAULT_HOBBING_MACHINE = "hobber-840d"
# The dialects the hobbing templates are written in (issue 30: the class templates render the
# coupling as EGON for the 840D, as G81/G80 for Fanuc and as the M series' G81.4/G80.4,
# engine.hobbing.dialects). A hobber of another dialect is refused by name here, not at the
# first line of a program written for another control.
HOBBING_DIALECTS_MADE = ("840d", "fanuc", "fanuc-g81.4")


def hobbing_machine(conn: Connection, name: str | None) -> Machine:
    """The machine record, which must be a hobbing machine (default: the seeded 840D hobber)."""
    machine = load_machine(conn, name or DEFAULT_HOBBING_MACHINE)
    if machine.kind != "hobber":
        raise EngineError(f"machine {machine.name} is a {machine.kind}, not a hobbing machine; "
                          f"use --machine {DEFAULT_HOBBING_MACHINE}")
    if machine.dialect not in HOBBING_DIALECTS_MADE:
        raise EngineError(f"machine {machine.name} runs dialect {machine.dialect}: the engine makes hobbing programs "
                          f"for {', '.join(HOBBING_DIALECTS_MADE)} only; "
                          f"use --machine {DEFAULT_HOBBING_MACHINE}")
    return machine


def load_machine(conn: Connection, name: str) -> Machine:
    """The record of that name; a name written in another case finds its one record, as
    `engine machines import` holds names that differ only in case to be one machine."""
    rows = conn.execute(MACHINE_QUERY + " WHERE name = %s", (name,)).fetchall() or \
        conn.execute(MACHINE_QUERY + " WHERE lower(name) = lower(%s)", (name,)).fetchall()
    if len(rows) != 1:
        known = ", ".join(r[0] for r in conn.execute("SELECT name FROM machine ORDER BY name"))
        raise EngineError(f"machine {name!r} does not exist; known machines: {known or 'none (run engine seed)'}")
    return as_float(Machine, rows[0], "machine")


def all_machines(conn: Connection) -> list[Machine]:
    """Every machine record, by name: what `--machine` accepts."""
    return [as_float(Machine, row, "machine") for row in conn.execute(MACHINE_QUERY + " ORDER BY name")]
