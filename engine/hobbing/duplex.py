"""Hobbing model of multi-unit (duplex) gears: further spur units on the same blank, each
below the one before, cut one after the other with the same hob. Unit 1 is the gear row
(top face at Z = 0); unit 2 comes from the gear_unit table with its own teeth, face width,
diameters and top face. The class inherits spur's rows; its own rows re-couple the table
for unit 2 (module sync 3) and cut it (cutmotion 3 and 4) with the unit's own parameters."""
from __future__ import annotations

import math

import msgspec

from ..errors import EngineError
from ..gears.models import register_model
from ..verifier import check_table_speed
from . import shifting
from .cylindrical import CylindricalModel, JobParameters
from .envelope import half_length, reach_into_cylinder
from .geometry import cut_depth
from .passes import plan_cuts, working_area

TOOTH_DEPTH_MODULES = 2.25
UNIT_MODULES = {1: (1, 2), 2: (3, 4)}   # unit → its cutmotion module numbers (rough, finish)
SYNC_PARAMETERS = frozenset({"unit", "z2", "b", "z_top"})
CLEARANCE = 1.0     # mm kept between the hob envelope and the unit not being cut
MIN_OVERRUN = 1.0   # mm the pass carries the hob centre beyond the face it leaves, at the least
# (other unit below, climb) → the pass end nearest the other unit: climb enters above the top
# face (z_from) and leaves below the bottom one (z_to); conventional the reverse.
FACING_END = {(True, True): "z_to", (True, False): "z_from", (False, True): "z_from", (False, False): "z_to"}


@register_model("duplex")
class DuplexModel(CylindricalModel):
    def parameter_names(self, t: str, n: int) -> frozenset:
        names = super().parameter_names(t, n)
        return names | SYNC_PARAMETERS if (t, n) == ("sync", 3) else names

    def job(self, gear, gear_class, hob, machine, cutting, choices) -> JobParameters:
        units = unit_gears(gear)
        setups = [self.setup(unit, hob) for unit in units]
        module_params = {}
        for number, (unit, setup) in enumerate(zip(units, setups), start=1):
            check_table_speed(gear.id, unit.teeth, hob.starts, cutting.hob_speed, machine)
            unit_cuts = self._unit_cuts(number, unit, hob, cutting, choices, setup)
            module_params.update(unit_cuts)
        module_params["sync:3"] = {"unit": 2, "z2": units[1].teeth, "b": units[1].face_width,
                                   "z_top": units[1].z_top}
        shift = shifting.parameters(choices, hob, gear)
        keep_clear(gear, hob, half_length(hob.length, shift), units, setups, module_params)
        x_retract = max(setup.x_retract for setup in setups)
        params = {**self.base_params(gear, gear_class, hob, machine, cutting, choices, setups[0]),
                  **shift, "x_retract": round(x_retract, 3)}
        cuts = [cut for cut in module_params.values() if cut.get("cut_on")]
        xs = [x_retract] + [cut["cut_x"] for cut in cuts]
        zs = [z for cut in cuts for z in (cut["z_from"], cut["z_to"])]
        params.update(working_area(xs, shifting.y_positions(params), zs + [params["z_start"]]))
        return self.for_machine(params, module_params, machine, hob)

    def _unit_cuts(self, number, unit, hob, cutting, choices, setup) -> dict:
        cuts = {}
        unit_choices = choices.for_unit(number, len(UNIT_MODULES), unit.id)
        for cut, module_number in zip(plan_cuts(unit.module, setup.full_depth, unit_choices), UNIT_MODULES[number]):
            params = self.cut_params(cut, unit, hob, cutting, setup)
            params["z_from"] = round(params["z_from"] + unit.z_top, 3)
            params["z_to"] = round(params["z_to"] + unit.z_top, 3)
            cuts[f"cutmotion:{module_number}"] = params
        return cuts


class UnitGear(msgspec.Struct, frozen=True):
    """A unit seen as a gear of its own (what the cylindrical formulas read), with its top face."""
    id: int
    module: float
    pressure_angle: float
    helix_angle: float
    hand: str | None
    teeth: int
    face_width: float
    tip_diameter: float
    root_diameter: float
    z_top: float

    @classmethod
    def of(cls, gear, teeth, face_width, tip_diameter, root_diameter, z_top) -> UnitGear:
        tip = tip_diameter or gear.module * (teeth + 2)
        root = root_diameter or tip - 2 * TOOTH_DEPTH_MODULES * gear.module
        return cls(gear.id, gear.module, gear.pressure_angle, gear.helix_angle, gear.hand, teeth,
                   face_width, tip, root, z_top)


def unit_gears(gear) -> list[UnitGear]:
    if not gear.units:
        raise EngineError(f"gear {gear.id}: class duplex cuts two units, the gear has 1; import its second "
                          f"unit with `engine gears units FILE.csv`")
    if len(gear.units) > 1:
        raise EngineError(f"gear {gear.id}: class duplex cuts two units per set-up (the gear row and unit 2), the "
                          f"gear has {1 + len(gear.units)}; import its units again with unit 2 alone (`engine gears "
                          f"units FILE.csv` replaces them) and cut the third toothing in a set-up of its own")
    if gear.helix_angle:
        raise EngineError(f"gear {gear.id}: class duplex derives from spur; helical units (β = "
                          f"{gear.helix_angle:g}°) need a class of their own")
    first = UnitGear.of(gear, gear.teeth, gear.face_width, gear.tip_diameter, gear.root_diameter, 0.0)
    second = gear.units[0]
    unit2 = UnitGear.of(gear, second.teeth, second.face_width, second.tip_diameter, second.root_diameter,
                     second.z_top)
    if unit2.z_top > -first.face_width:
        raise EngineError(f"gear {gear.id}: unit 2 starts at Z{unit2.z_top:g}, inside unit 1 "
                          f"(Z0…{-first.face_width:g}); correct z_top in gear_unit")
    return [first, unit2]


def keep_clear(gear, hob, extent, units, setups, module_params) -> None:
    """Every cut of one unit keeps the hob envelope (tip cylinder, length, swivel) clear of the
    other unit by CLEARANCE: at the infeed (approach Z), along the axial pass and at the G0 X
    retract at the end Z, all at the cut's centre distance or further out, so the hull of the
    pass at cut_x covers them. Where the run-out faces the other unit it is shortened, as long as
    the pass still carries the hob centre beyond the face (design notes §7, shortest_overrun); the
    run-in is never shortened (the infeed must stay clear of the unit being cut)."""
    for number, (unit, setup) in enumerate(zip(units, setups), start=1):
        other_number = 3 - number
        for module_number in UNIT_MODULES[number]:
            cut = module_params[f"cutmotion:{module_number}"]
            if cut["cut_on"]:
                _keep_cut_clear(gear, (hob, extent), setup, (number, unit),
                                (other_number, units[other_number - 1]), cut)


def _keep_cut_clear(gear, hob_extent, setup, numbered_unit, numbered_other, cut) -> None:
    (hob, extent), (number, unit), (other_number, other) = hob_extent, numbered_unit, numbered_other
    reach = reach_into_cylinder(hob.tip_diameter / 2, extent, setup.swivel, cut["cut_x"],
                                other.tip_diameter / 2 + CLEARANCE)
    if reach is None:
        return
    below = other.z_top < unit.z_top
    toward = -1 if below else 1                             # Z direction from this unit to the other
    face, other_face = facing_faces(unit, other, below)
    limit = other_face - toward * (CLEARANCE + reach)       # furthest hob centre Z toward the other
    end = FACING_END[below, cut["climb"]]
    if toward * (cut[end] - limit) <= 0:
        return
    least = shortest_overrun(unit, hob, setup.swivel, cut["cut_x"]) if end == "z_to" else toward * (cut[end] - face)
    shortened = _rounded_inward(limit, toward)
    if end == "z_to" and toward * (shortened - face) >= least:
        cut["z_to"] = shortened
        return
    raise EngineError(
        f"gear {gear.id}: cutting unit {number} ({cut['cut_name']} at X{cut['cut_x']:g}) the hob "
        f"{hob.id} (da0 {hob.tip_diameter:g}, swivel {setup.swivel:.2f}°) reaches {reach:.1f} mm along Z "
        f"into unit {other_number} (tip Ø{other.tip_diameter:g}); the units need "
        f"{least + CLEARANCE + reach:.1f} mm between their faces, they have {abs(other_face - face):.1f}; "
        f"use a smaller hob, a wider gap between the units or another class; nothing stored")


def facing_faces(unit, other, other_below: bool) -> tuple[float, float]:
    """(Z of this unit's face toward the other, Z of the other's face toward this one)."""
    if other_below:
        return unit.z_top - unit.face_width, other.z_top
    return unit.z_top, other.z_top - other.face_width


def shortest_overrun(unit, hob, swivel: float, cut_x: float) -> float:
    """The least run-out that still finishes the face it leaves: the hob centre MIN_OVERRUN
    beyond it, plus the axial projection of the generating zone (h/tan α_n)·sin η of a
    swivelled hob (reference §B8)."""
    depth = cut_depth(unit.tip_diameter, hob.tip_diameter, cut_x)
    zone = depth / math.tan(math.radians(unit.pressure_angle)) * math.sin(math.radians(abs(swivel)))
    return MIN_OVERRUN + zone


def _rounded_inward(z: float, toward: int) -> float:
    """z rounded to the program's 0.001 mm away from the other unit."""
    return (math.floor if toward > 0 else math.ceil)(z * 1000) / 1000
