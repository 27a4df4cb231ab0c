"""Workpieces, hobs and machines as read from the database."""
from __future__ import annotations

from dataclasses import dataclass, fields

from ..errors import EngineError


@dataclass(frozen=True)
class Gear:
    id: int
    gear_class: str | None
    module: float
    teeth: int
    pressure_angle: float
    helix_angle: float
    hand: str | None
    face_width: float
    tip_diameter: float | None
    root_diameter: float | None
    cone_angle: float | None
    crowning: float | None
    material: str | None
    hardness: float | None
    quality_grade: int | None
    quantity: int | None
    units: tuple = ()          # further toothed units of a multi-unit gear (GearUnit), unit 2 first


@dataclass(frozen=True)
class GearUnit:
    """A further toothed unit of a multi-unit (duplex) gear, cut with the gear's hob."""
    unit: int
    teeth: int
    face_width: float
    tip_diameter: float | None
    root_diameter: float | None
    z_top: float               # Z of the unit's upper face (the gear's top face is Z = 0)


@dataclass(frozen=True)
class Hob:
    id: str
    module: float
    pressure_angle: float
    starts: int
    tip_diameter: float
    length: float
    hand: str
    accuracy_class: str
    material: str
    coating: str
    purpose: str


@dataclass(frozen=True)
class Machine:
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


def _columns(record_type, exclude=frozenset()) -> str:
    return ", ".join(field.name for field in fields(record_type) if field.name not in exclude)


def _as_float(record_type, row) -> object:
    """numeric columns arrive as Decimal; models compute in float."""
    from decimal import Decimal

    return record_type(*(float(v) if isinstance(v, Decimal) else v for v in row))


GEAR_QUERY = f"SELECT {_columns(Gear, exclude={'units'})} FROM gear"  # static, from the dataclass
UNIT_QUERY = f"SELECT gear_id, {_columns(GearUnit)} FROM gear_unit"
HOB_QUERY = f"SELECT {_columns(Hob)} FROM hob"
MACHINE_QUERY = f"SELECT {_columns(Machine)} FROM machine"


def load_gear(conn, gear_id: int) -> Gear:
    row = conn.execute(GEAR_QUERY + " WHERE id = %s", (gear_id,)).fetchone()
    if row is None:
        raise EngineError(f"gear {gear_id} does not exist; import it with `engine gears import FILE.csv`")
    return _with_units(_as_float(Gear, row), _load_units(conn, gear_id, gear_id))


def load_gears(conn, first: int | None = None, last: int | None = None) -> list[Gear]:
    rows = conn.execute(GEAR_QUERY + " WHERE id BETWEEN %s AND %s ORDER BY id",
                        (first if first is not None else 0, last if last is not None else 2**31 - 1))
    gears = [_as_float(Gear, row) for row in rows]
    if not gears:
        return gears
    units = _load_units(conn, gears[0].id, gears[-1].id)
    return [_with_units(gear, units) for gear in gears]


def _load_units(conn, first: int, last: int) -> dict[int, tuple]:
    """Further units of the gears first…last, by gear id, in unit order."""
    found: dict[int, list] = {}
    for row in conn.execute(UNIT_QUERY + " WHERE gear_id BETWEEN %s AND %s ORDER BY gear_id, unit", (first, last)):
        found.setdefault(row[0], []).append(_as_float(GearUnit, row[1:]))
    return {gear_id: tuple(units) for gear_id, units in found.items()}


def _with_units(gear: Gear, units: dict) -> Gear:
    from dataclasses import replace

    return replace(gear, units=units.get(gear.id, ())) if gear.id in units else gear


def load_hobs(conn) -> list[Hob]:
    return [_as_float(Hob, row) for row in conn.execute(HOB_QUERY + " ORDER BY id")]


DEFAULT_HOBBING_MACHINE = "hobber-840d"


def hobbing_machine(conn, name: str | None) -> Machine:
    """The machine record, which must be a hobbing machine (default: the seeded 840D hobber)."""
    machine = load_machine(conn, name or DEFAULT_HOBBING_MACHINE)
    if machine.kind != "hobber":
        raise EngineError(f"machine {machine.name} is a {machine.kind}, not a hobbing machine; "
                          f"use --machine {DEFAULT_HOBBING_MACHINE}")
    return machine


def load_machine(conn, name: str) -> Machine:
    row = conn.execute(MACHINE_QUERY + " WHERE name = %s", (name,)).fetchone()
    if row is None:
        known = ", ".join(r[0] for r in conn.execute("SELECT name FROM machine ORDER BY name"))
        raise EngineError(f"machine {name!r} does not exist; known machines: {known or 'none (run engine seed)'}")
    return _as_float(Machine, row)
