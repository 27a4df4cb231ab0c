"""Workpieces and hobs as read from the database (machines: engine.machines.records)."""
from __future__ import annotations

import math
from collections.abc import Callable
from decimal import Decimal
from functools import partial
from typing import TYPE_CHECKING, Any

import msgspec
from msgspec.structs import replace

from ..db.records import as_float, columns
from ..errors import EngineError
from .hob_geometry import hob_axial_module, normal_from_axial

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..db.connection import Connection
    from ..db.records import Record

TOOTH_DEPTH = Decimal("2.25")  # full tooth depth in modules: root = tip − 2·2.25·m


class CuttingSpeeds(msgspec.Struct, frozen=True):
    """A material's §C row (table material, engine.gears.speed_table): (lowest, highest) v
    [m/min] per hob column of TOOLS, and the v a job with no machining history takes with an
    uncoated and with a coated hob [m/min]."""
    ranges: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]
    defaults: tuple[float, float]


class Gear(msgspec.Struct, frozen=True):
    """A workpiece record (table gear, with its units): what the hobbing models and the simulation read."""
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
    # How the drawing stated the module: 'normal', 'axial' (a worm wheel's: the worm's axial module,
    # converted on load, so `module` is always the normal module the models compute with), or None
    # (not stated: normal for cylindrical gears; the worm-wheel model refuses it).
    module_kind: str | None = None
    profile_shift: float | None = None   # x [modules] as the drawing gives it (None: not given)
    units: tuple = ()          # further toothed units of a multi-unit gear (GearUnit), unit 2 first
    # The §C row of its material, from table material (None: no material, or one the table lacks;
    # engine.gears.speed_table then reads the seed rows). Not a field of the gear's own record.
    cutting_speeds: CuttingSpeeds | None = None

    @property
    def stated_module(self) -> float:
        """The module as the drawing gives it (the axial module of an axial-stated worm wheel)."""
        return axial_module(self.module, self.helix_angle) if self.module_kind == "axial" else self.module


class GearUnit(msgspec.Struct, frozen=True):
    """A further toothed unit of a multi-unit (duplex) gear, cut with the gear's hob."""
    unit: int
    teeth: int
    face_width: float
    tip_diameter: float | None
    root_diameter: float | None
    z_top: float               # Z of the unit's upper face (the gear's top face is Z = 0)


class Hob(msgspec.Struct, frozen=True):
    """A hob of the library (table hob): its size, starts and hand, which engine.gears.hob_matching checks against a
    gear."""
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
    tool_number: int = 1
    # The module the record gives: 'normal', or 'axial' (a worm-wheel hob catalogued by its worm's
    # axial module, DIN 3975: converted on load, so `module` is always the normal module m_n).
    module_kind: str = "normal"
    # Gashes (flutes) of the hob: with the starts they set how many cutting edges share one
    # workpiece revolution's feed (Hoffmeister's i = gashes/starts, reference §C1). The migration's
    # default, 12, is the usual count of solid HSS catalogue hobs of m1–m4 [K].
    gashes: int = 12
    # The hob's tooth profile (reference §C1): standard (the basic rack profile, DIN 3972),
    # protuberance (a tip protuberance undercutting the root ahead of shaving or grinding) or
    # topping (the hob's root also cuts the gear's tip diameter).
    profile: str = "standard"

    @property
    def stated_module(self) -> float:
        """The module as the record gives it (the axial module m_x of an axial-stated hob)."""
        if self.module_kind == "axial":   # to 1e-9 mm: the record's value back, not its last bit
            return round(hob_axial_module(self.module, self.starts, self.tip_diameter), 9)
        return self.module


def normal_module(module: Any, module_kind: str | None, helix_angle: Any) -> Any:
    """m_n = m_x·cos γ for a module stated as the worm's axial module (γ, the worm's lead angle,
    is the wheel's helix angle: reference §B10, ΔC = 360·ΔY/(π·m_x·z2) = 360·cos γ·ΔY/(π·m_n·z2));
    a normal or unstated module as it is. Decimal in, Decimal out."""
    if module_kind != "axial":
        return module
    cos_gamma = math.cos(math.radians(float(helix_angle)))
    return module * Decimal(repr(cos_gamma)) if isinstance(module, Decimal) else module * cos_gamma


def axial_module(normal: float, helix_angle: float) -> float:
    return normal / math.cos(math.radians(helix_angle))


def reference_diameter(module: Any, teeth: int, helix_angle: Any = 0) -> Any:
    """d = m·z / cos β (β in degrees), exact for a spur gear; Decimal in, Decimal out."""
    if helix_angle == 0:
        return module * teeth
    cos_beta = math.cos(math.radians(float(helix_angle)))
    if isinstance(module, Decimal):
        return module * teeth / Decimal(repr(cos_beta))
    return module * teeth / cos_beta


def derived_diameters(module: Any, teeth: int, helix_angle: Any = 0,
                      tip_diameter: Any = None, root_diameter: Any = None) -> tuple[Any, Any]:
    """(tip, root) diameters: the given ones, else tip = d + 2m and root = tip − 2·2.25·m
    (so a given tip that includes profile shift keeps the full tooth depth 2.25 m)."""
    tip = tip_diameter
    if tip is None:
        tip = reference_diameter(module, teeth, helix_angle) + 2 * module
    root = root_diameter
    if root is None:
        depth = TOOTH_DEPTH if isinstance(module, Decimal) else float(TOOTH_DEPTH)
        root = tip - 2 * depth * module
    return tip, root


def _as_float(record_type: type[Record], row: Sequence[Any]) -> Record:
    return as_float(record_type, row, _KINDS.get(record_type, "record"))


_KINDS = {Gear: "gear", GearUnit: "unit", Hob: "hob"}
GEAR_QUERY = f"SELECT {columns(Gear, exclude={'units', 'cutting_speeds'})} FROM gear"  # static: the record's fields
UNIT_QUERY = f"SELECT gear_id, {columns(GearUnit)} FROM gear_unit"
HOB_QUERY = f"SELECT {columns(Hob)} FROM hob"


def load_gear(conn: Connection, gear_id: int) -> Gear:
    row = conn.execute(GEAR_QUERY + " WHERE id = %s", (gear_id,)).fetchone()
    if row is None:
        raise EngineError(f"gear {gear_id} does not exist; import it with `engine gears import FILE.csv`")
    gear = _with_units(_completed(_as_float(Gear, row)), _load_units(conn, gear_id, gear_id))
    return with_speeds(gear, load_cutting_speeds(conn))


def load_gears(conn: Connection, first: int | None = None, last: int | None = None,
               refused: dict | None = None) -> list[Gear]:
    """The gears first…last; with `refused`, a gear that cannot be completed is left out and its
    message kept there by id (a batch names every bad gear), else it stops the load."""
    rows = conn.execute(GEAR_QUERY + " WHERE id BETWEEN %s AND %s ORDER BY id",
                        (first if first is not None else 0, last if last is not None else 2**31 - 1))
    gears = [gear for gear in (_completed_or_refused(_as_float(Gear, row), refused) for row in rows) if gear]
    if not gears:
        return gears
    units = _load_units(conn, gears[0].id, gears[-1].id)
    whole = (_or_refused(partial(_with_units, gear, units), gear.id, refused) for gear in gears)
    speeds = load_cutting_speeds(conn)
    return [with_speeds(gear, speeds) for gear in whole if gear]


SPEEDS_QUERY = """SELECT lower(name), uncoated_low, uncoated_high, coated_low, coated_high, carbide_low, carbide_high,
       default_uncoated, default_coated FROM material"""


def load_cutting_speeds(conn: Connection) -> dict[str, CuttingSpeeds]:
    """The §C row of every material of table material, by its name in lower case (a gear's
    material is matched ignoring case), in m/min."""
    rows = {}
    for name, *v in conn.execute(SPEEDS_QUERY):
        v = [float(value) for value in v]
        rows[name] = CuttingSpeeds(((v[0], v[1]), (v[2], v[3]), (v[4], v[5])), (v[6], v[7]))
    return rows


def with_speeds(gear: Gear, speeds: dict[str, CuttingSpeeds]) -> Gear:
    """The gear with the §C row of its material (none for a material the table lacks: the planner
    refuses it, engine.programs.instantiate)."""
    row = speeds.get((gear.material or "").strip().lower())
    return replace(gear, cutting_speeds=row) if row is not None else gear


def _completed_or_refused(gear: Gear, refused: dict | None) -> Gear | None:
    return _or_refused(lambda: _completed(gear), gear.id, refused)


def _or_refused(complete: Callable[[], Gear], gear_id: int, refused: dict | None) -> Gear | None:
    """complete(), or with `refused` None and its message kept by the gear's id (a batch names every bad gear)."""
    if refused is None:
        return complete()
    try:
        return complete()
    except EngineError as error:
        refused[gear_id] = str(error)
        return None


def _completed(gear: Gear) -> Gear:
    """The module as the normal module; a gear written in SQL without its diameters gets them as
    a CSV import computes them."""
    if gear.module_kind == "axial":
        gear = replace(gear, module=normal_module(gear.module, gear.module_kind, gear.helix_angle))
    if gear.tip_diameter is not None and gear.root_diameter is not None:
        return gear
    tip, root = derived_diameters(gear.module, gear.teeth, gear.helix_angle, gear.tip_diameter, gear.root_diameter)
    if not 0 < root < tip:
        raise EngineError(f"gear {gear.id}: its computed root diameter {root:g} is not between 0 and the tip "
                          f"diameter {tip:g}; give tip_diameter and root_diameter")
    return replace(gear, tip_diameter=tip, root_diameter=root)


def _load_units(conn: Connection, first: int, last: int) -> dict[int, tuple]:
    """Further units of the gears first…last, by gear id, in unit order."""
    found: dict[int, list] = {}
    for row in conn.execute(UNIT_QUERY + " WHERE gear_id BETWEEN %s AND %s ORDER BY gear_id, unit", (first, last)):
        found.setdefault(row[0], []).append(_as_float(GearUnit, row[1:]))
    return {gear_id: tuple(units) for gear_id, units in found.items()}


def _with_units(gear: Gear, units: dict) -> Gear:
    """The gear with its further units, each completed as the gear is (_completed_unit)."""
    if gear.id not in units:
        return gear
    return replace(gear, units=tuple(_completed_unit(gear, unit) for unit in units[gear.id]))


def _completed_unit(gear: Gear, unit: GearUnit) -> GearUnit:
    """A unit written in SQL without its diameters gets them as `engine gears import` computes a
    unit's: spur teeth of the gear's module (engine.gears.units). Before, the simulation met
    the missing root as a bug (exit 2) in the middle of a batch."""
    if unit.tip_diameter is not None and unit.root_diameter is not None:
        return unit
    tip, root = derived_diameters(gear.module, unit.teeth, 0, unit.tip_diameter, unit.root_diameter)
    if not 0 < root < tip:
        raise EngineError(f"gear {gear.id} unit {unit.unit}: its computed root diameter {root:g} is not between 0 "
                          f"and the tip diameter {tip:g}; give the unit's tip_diameter and root_diameter")
    return replace(unit, tip_diameter=tip, root_diameter=root)


def load_hobs(conn: Connection) -> list[Hob]:
    return [_normal(_as_float(Hob, row)) for row in conn.execute(HOB_QUERY + " ORDER BY id")]


def _normal(hob: Hob) -> Hob:
    """The hob with its normal module: an axial module converted once, here (hob_geometry)."""
    if hob.module_kind != "axial":
        return hob
    return replace(hob, module=normal_from_axial(hob.module, hob.starts, hob.tip_diameter))
