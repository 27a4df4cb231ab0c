"""Hobbing model of multi-unit (duplex) gears: further spur units on the same blank, each
below the one before, cut one after the other with the same hob. Unit 1 is the gear row
(top face at Z = 0); unit 2 comes from the gear_unit table with its own teeth, face width,
diameters and top face. The class inherits spur's rows; its own rows re-couple the table
for unit 2 (module sync 3) and cut it (cutmotion 3 and 4) with the unit's own parameters."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import EngineError
from ..programs.verifier import check_table_speed
from . import shifting
from .cylindrical import CylindricalModel, JobParameters
from .passes import plan_cuts, working_area

TOOTH_DEPTH_MODULES = 2.25
UNIT_MODULES = {1: (1, 2), 2: (3, 4)}   # unit → its cutmotion module numbers (rough, finish)
SYNC_PARAMETERS = frozenset({"unit", "z2", "b", "z_top"})


class DuplexModel(CylindricalModel):
    def parameter_names(self, t: str, n: int) -> frozenset:
        names = super().parameter_names(t, n)
        return names | SYNC_PARAMETERS if (t, n) == ("sync", 3) else names

    def job(self, gear, gear_class, hob, machine, cutting, choices) -> JobParameters:
        units = unit_gears(gear)
        setups = [self.setup(unit, hob) for unit in units]
        module_params, passes = {}, []
        for number, (unit, setup) in enumerate(zip(units, setups), start=1):
            check_table_speed(gear.id, unit.teeth, hob.starts, cutting.hob_speed, machine)
            unit_cuts = self._unit_cuts(number, unit, hob, cutting, choices, setup)
            module_params.update(unit_cuts)
            passes.append((unit, setup, [c for c in unit_cuts.values() if c["cut_on"]]))
        module_params["sync:3"] = {"unit": 2, "z2": units[1].teeth, "b": units[1].face_width,
                                   "z_top": units[1].z_top}
        check_clearance(gear, hob, passes)
        x_retract = max(setup.x_retract for setup in setups)
        params = {**self.base_params(gear, gear_class, hob, machine, cutting, choices, setups[0]),
                  **shifting.parameters(choices, hob, gear), "x_retract": round(x_retract, 3)}
        xs = [x_retract] + [cut["cut_x"] for _, _, cuts in passes for cut in cuts]
        zs = [z for _, _, cuts in passes for cut in cuts for z in (cut["z_from"], cut["z_to"])]
        params.update(working_area(xs, shifting.y_positions(params), zs + [params["z_start"]]))
        return self.for_machine(params, module_params, machine, hob)

    def _unit_cuts(self, number, unit, hob, cutting, choices, setup) -> dict:
        cuts = {}
        for cut, module_number in zip(plan_cuts(unit.module, setup.full_depth, choices), UNIT_MODULES[number]):
            params = self.cut_params(cut, unit, hob, cutting, setup)
            params["z_from"] = round(params["z_from"] + unit.z_top, 3)
            params["z_to"] = round(params["z_to"] + unit.z_top, 3)
            cuts[f"cutmotion:{module_number}"] = params
        return cuts


@dataclass(frozen=True)
class UnitGear:
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
    def of(cls, gear, teeth, face_width, tip_diameter, root_diameter, z_top) -> "UnitGear":
        tip = tip_diameter or gear.module * (teeth + 2)
        root = root_diameter or tip - 2 * TOOTH_DEPTH_MODULES * gear.module
        return cls(gear.id, gear.module, gear.pressure_angle, gear.helix_angle, gear.hand, teeth,
                   face_width, tip, root, z_top)


def unit_gears(gear) -> list[UnitGear]:
    if len(gear.units) != 1:
        raise EngineError(f"gear {gear.id}: class duplex cuts exactly two units, the gear has "
                          f"{1 + len(gear.units)}; import its second unit with `engine gears units FILE.csv`")
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


def check_clearance(gear, hob, passes) -> None:
    """The hob, while cutting one unit, must not reach the other: where the other unit's tip
    cylinder lies within the hob's tip radius, the hob touches it over a half-chord along Z
    around its centre; every hob centre Z of the pass keeps that far from the other unit's faces."""
    hob_radius = hob.tip_diameter / 2
    for unit, setup, cuts in passes:
        for other, _, _ in passes:
            if other is unit or not cuts:
                continue
            gap = min(cut["cut_x"] for cut in cuts) - other.tip_diameter / 2
            if gap >= hob_radius:
                continue
            half_chord = math.sqrt(hob_radius ** 2 - gap ** 2)
            low = min(min(c["z_from"], c["z_to"]) for c in cuts) - half_chord
            high = max(max(c["z_from"], c["z_to"]) for c in cuts) + half_chord
            other_top, other_bottom = other.z_top, other.z_top - other.face_width
            if low < other_top and high > other_bottom:
                raise EngineError(
                    f"gear {gear.id}: cutting the unit at Z{unit.z_top:g} the hob (da0 {hob.tip_diameter:g}) "
                    f"reaches Z{low:.1f}…{high:.1f}, into the unit at Z{other_top:g}…{other_bottom:g}; "
                    f"the units need a wider gap (or a smaller hob); nothing stored")

