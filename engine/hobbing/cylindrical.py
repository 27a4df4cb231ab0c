"""Hobbing model of cylindrical gears (spur and helical): the parameters their standard
code needs. Formulas: reference/hobbing.md §B."""
from __future__ import annotations

from dataclasses import dataclass

from ..cutting_data import CuttingData, per_minute
from ..records import Gear, Hob, Machine
from . import geometry
from .choices import Choices

APPROACH_SAFETY = 2.0     # mm added to the run-in E (§B7: 1–3 mm)
RETRACT_CLEARANCE = 5.0   # mm between hob tip and gear tip when retracted
LIMIT_MARGIN = 1.0        # mm between the outermost move and the working-area limit
CUT_NAMES = {1: "ROUGH", 2: "FINISH"}


@dataclass(frozen=True)
class JobParameters:
    params: dict
    module_params: dict


JOB_PARAMETERS = frozenset({
    "program_name", "gear_id", "gear_class", "mn", "z2", "alpha_n", "beta", "hand", "b", "da2", "df2",
    "hob_id", "z0", "da0", "hob_hand", "machine", "n0", "cuts", "coolant", "climb", "swivel",
    "lead_angle", "x_retract", "z_start", "z_end", "x_lower", "x_upper", "y_lower", "y_upper",
    "z_lower", "z_upper", "shift_on", "shift_y", "template_version",
})
CUT_PARAMETERS = frozenset({"cut_name", "cut_x", "feed_radial", "feed_axial", "cut_on"})


class CylindricalModel:
    """Spur and helical gears: radial infeed in air, axial pass with overrun, per cut."""

    def parameter_names(self, t: str, n: int) -> frozenset:
        return JOB_PARAMETERS | (CUT_PARAMETERS if t == "cutmotion" else frozenset())

    def job(self, gear: Gear, gear_class: str, hob: Hob, machine: Machine,
            cutting: CuttingData, choices: Choices) -> JobParameters:
        lead = geometry.lead_angle(hob.module, hob.starts, hob.tip_diameter)
        swivel = geometry.swivel_angle(gear.helix_angle, gear.hand, lead, hob.hand)
        full_depth = geometry.full_depth_centre_distance(gear.root_diameter, hob.tip_diameter)
        depth = geometry.cut_depth(gear.tip_diameter, hob.tip_diameter, full_depth)
        z_start = geometry.approach_length(depth, hob.tip_diameter, gear.tip_diameter, swivel) + APPROACH_SAFETY
        z_end = -gear.face_width - geometry.overrun_length(gear.module, depth, gear.pressure_angle, swivel)
        x_retract = (gear.tip_diameter + hob.tip_diameter) / 2 + RETRACT_CLEARANCE
        cuts = self._cuts(gear, hob, cutting, choices, full_depth)
        params = {
            "program_name": f"GEAR{gear.id}", "gear_id": gear.id, "gear_class": gear_class,
            "mn": gear.module, "z2": gear.teeth, "alpha_n": gear.pressure_angle, "beta": gear.helix_angle,
            "hand": gear.hand or "", "b": gear.face_width, "da2": gear.tip_diameter, "df2": gear.root_diameter,
            "hob_id": hob.id, "z0": hob.starts, "da0": hob.tip_diameter, "hob_hand": hob.hand,
            "machine": machine.name, "n0": cutting.hob_speed, "cuts": choices.cut_count(gear.module),
            "coolant": choices.coolant, "climb": choices.climb, "swivel": round(swivel, 4),
            "lead_angle": round(lead, 4), "x_retract": round(x_retract, 3),
            "z_start": round(z_start, 3), "z_end": round(z_end, 3),
            "shift_on": choices.shift_y != 0, "shift_y": choices.shift_y,
            **self._limits(full_depth, x_retract, z_start, z_end, choices.shift_y),
        }
        return JobParameters(params, cuts)

    def _cuts(self, gear, hob, cutting, choices, full_depth) -> dict:
        two_cuts = choices.cut_count(gear.module) == 2
        rough_x = full_depth + choices.stock(gear.module)
        plan = {1: (rough_x, cutting.axial_feed_rough, two_cuts),
                2: (full_depth, cutting.axial_feed_finish if two_cuts else cutting.axial_feed_rough, True)}
        cuts = {}
        for number, (centre_distance, axial, on) in plan.items():
            cuts[f"cutmotion:{number}"] = {
                "cut_name": CUT_NAMES[number] if two_cuts else "SINGLE",
                "cut_x": round(centre_distance, 3),
                "feed_axial": round(per_minute(axial, cutting.hob_speed, hob.starts, gear.teeth), 1),
                "feed_radial": round(per_minute(cutting.radial_feed, cutting.hob_speed, hob.starts, gear.teeth), 1),
                "cut_on": on,
            }
        return cuts

    @staticmethod
    def _limits(full_depth, x_retract, z_start, z_end, shift_y) -> dict:
        return {
            "x_lower": round(full_depth - LIMIT_MARGIN, 3), "x_upper": round(x_retract + LIMIT_MARGIN, 3),
            "y_lower": round(min(0.0, shift_y) - LIMIT_MARGIN, 3), "y_upper": round(max(0.0, shift_y) + LIMIT_MARGIN, 3),
            "z_lower": round(z_end - LIMIT_MARGIN, 3), "z_upper": round(z_start + LIMIT_MARGIN, 3),
        }
