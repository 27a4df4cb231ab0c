"""Hobbing model of cylindrical gears (spur and helical): the parameters their standard
code needs. Formulas: docs/reference/hobbing.md §B. The other classes' models derive from it."""
from __future__ import annotations

from typing import Protocol

import msgspec

from ..gears.cutting_data import CuttingData
from ..gears.models import register_model
from ..gears.records import Gear, Hob
from ..machines.records import Machine
from . import conventions, geometry, shifting
from .choices import Choices
from .machine_job import SETUP_PARAMETERS, machine_job
from .passes import Cut, Reach, feeds, hob_reach, pass_ends, plan_cuts, working_area

RETRACT_CLEARANCE = 5.0   # mm between hob tip and gear tip when retracted
# The infeed at the approach Z is in air: rapid to this far outside the cut's centre distance,
# then feed. The run-in clears the blank at the cut's own X, so any X beyond it is clear too;
# the millimetre absorbs the rapid's following error before the feed takes over.
RAPID_SHORT_OF_CUT = 1.0


class GearShape(Protocol):
    """What setup reads of a gear (mm, degrees): a Gear, or one unit of a duplex gear (UnitGear)."""

    @property
    def module(self) -> float: ...
    @property
    def pressure_angle(self) -> float: ...
    @property
    def helix_angle(self) -> float: ...
    @property
    def hand(self) -> str | None: ...
    @property
    def tip_diameter(self) -> float | None: ...
    @property
    def root_diameter(self) -> float | None: ...


class JobParameters(msgspec.Struct, frozen=True):
    """A job's parameters, and those of its modules, as the template reads them."""
    params: dict
    module_params: dict


JOB_PARAMETERS = frozenset({
    "program_name", "gear_id", "gear_class", "mn", "z2", "alpha_n", "beta", "hand", "b", "da2", "df2",
    "hob_id", "z0", "da0", "hob_hand", "machine", "n0", "cuts", "coolant", "tailstock", "feed_mode",
    "swivel", "lead_angle", "x_retract", "z_start", "z_end", "x_lower", "x_upper", "y_lower", "y_upper",
    "z_lower", "z_upper", "shift_on", "shift_y", "shift_per_part", "shift_min", "shift_max",
    "template_version", "coupling_b", "differential", "allowance", "fixture_id",
}) | SETUP_PARAMETERS
CUT_PARAMETERS = frozenset({"cut_name", "cut_x", "feed_radial", "feed_axial", "cut_on", "climb",
                            "z_from", "z_to", "x_air"})


class Setup(msgspec.Struct, frozen=True):
    """What every cut of a job shares: hob setting, full depth, reach and retract position."""
    lead: float
    swivel: float
    full_depth: float
    reach: Reach
    x_retract: float


def program_name(gear_id: int) -> str:
    """A hobbing program is named after its gear: GEAR<id> (the file GEAR<id>.MPF on the control)."""
    return f"GEAR{gear_id}"


@register_model("cylindrical")
class CylindricalModel:
    """Spur and helical gears: radial infeed in air, axial pass with overrun, per cut."""

    hob_purpose = "cylindrical"
    cut_shape = "axial"       # the pass its template emits (engine.hobbing.cycle_time.PASSES)
    axial_passes = True    # the cuts are axial passes, climb or conventional (--feed-mode)
    class_parameters: frozenset = frozenset()
    cut_parameters: frozenset = CUT_PARAMETERS

    def parameter_names(self, t: str, n: int) -> frozenset:
        names = JOB_PARAMETERS | self.class_parameters
        return names | (self.cut_parameters if t == "cutmotion" else frozenset())

    def shift_travel(self, choices: Choices) -> float:
        """Hob length the shift choice needs beyond the generating zone (for hob matching)."""
        return shifting.travel_needed(choices)

    def setup(self, gear: GearShape, hob: Hob) -> Setup:
        assert gear.root_diameter is not None and gear.tip_diameter is not None   # a loaded gear is completed
        lead = geometry.lead_angle(hob.module, hob.starts, hob.tip_diameter)
        swivel = conventions.swivel(gear.helix_angle, gear.hand, lead, hob.hand)
        full_depth = geometry.full_depth_centre_distance(gear.root_diameter, hob.tip_diameter)
        reach = hob_reach(gear, hob.tip_diameter, swivel, full_depth)
        x_retract = (gear.tip_diameter + hob.tip_diameter) / 2 + RETRACT_CLEARANCE
        return Setup(lead, swivel, full_depth, reach, x_retract)

    def job(self, gear: Gear, gear_class: str, hob: Hob, machine: Machine,
            cutting: CuttingData, choices: Choices) -> JobParameters:
        choices = choices.for_unit(1, 1, gear.id)   # a mode per unit is a cluster gear's
        setup = self.setup(gear, hob)
        cuts = plan_cuts(gear.module, setup.full_depth, choices)
        module_params = {f"cutmotion:{cut.number}": self.cut_params(cut, gear, hob, cutting, setup)
                         for cut in cuts}
        shift = shifting.parameters(choices, hob, gear)
        params = {**self.base_params(gear, gear_class, hob, machine, cutting, choices, setup),
                  **shift, **self.class_params(gear, hob, setup, choices)}
        xs, zs = self.extents(gear, setup, [module_params[f"cutmotion:{cut.number}"] for cut in cuts if cut.on])
        params.update(working_area(xs, shifting.y_positions(shift), zs + [params["z_start"]]))
        return self.for_machine(params, module_params, machine, hob)

    def for_machine(self, params: dict, module_params: dict, machine: Machine, hob: Hob) -> JobParameters:
        """The DIN-frame job in the machine's senses, with its setup and cycle time."""
        return JobParameters(*machine_job(params, module_params, machine, hob, self.cut_shape))

    @staticmethod
    def base_params(gear, gear_class, hob, machine, cutting, choices, setup) -> dict:
        return {
            "program_name": program_name(gear.id), "gear_id": gear.id, "gear_class": gear_class,
            "mn": gear.module, "z2": gear.teeth, "alpha_n": gear.pressure_angle, "beta": gear.helix_angle,
            "hand": gear.hand or "", "b": gear.face_width, "da2": gear.tip_diameter, "df2": gear.root_diameter,
            "hob_id": hob.id, "z0": hob.starts, "da0": hob.tip_diameter, "hob_hand": hob.hand,
            "machine": machine.name, "n0": cutting.hob_speed, "cuts": choices.cut_count(gear.module),
            "coolant": choices.coolant, "tailstock": choices.tailstock, "feed_mode": choices.mode,
            "swivel": round(setup.swivel, 6), "lead_angle": round(setup.lead, 4),
            "coupling_b": conventions.coupling_numerator(hob.starts, hob.hand),
            "differential": round(conventions.differential(gear.module, gear.teeth, gear.helix_angle, gear.hand), 6),
            "x_retract": round(setup.x_retract, 3),
            "z_start": round(setup.reach.approach, 3),
            "z_end": round(-gear.face_width - setup.reach.overrun, 3),
            "allowance": choices.allowance,   # mm radial, left at the final cut (passes.plan_cuts)
            "fixture_id": "",   # the job's work-holding, set by the planner (engine.gears.holding_matching)
        }

    def class_params(self, gear: Gear, hob: Hob, setup: Setup, choices: Choices) -> dict:
        return {}

    def cut_params(self, cut: Cut, gear: Gear, hob: Hob, cutting: CuttingData, setup: Setup) -> dict:
        z_from, z_to = pass_ends(setup.reach, 0.0, -gear.face_width, cut.climb)
        return {"cut_name": cut.name, "cut_x": round(cut.centre_distance, 3), "cut_on": cut.on,
                "x_air": round(cut.centre_distance + RAPID_SHORT_OF_CUT, 3),
                "climb": cut.climb, "z_from": round(z_from, 3), "z_to": round(z_to, 3),
                **feeds(cut, cutting, hob.starts, gear.teeth)}

    def extents(self, gear: Gear, setup: Setup, cuts: list[dict]) -> tuple[list, list]:
        """The X and Z positions the program moves to (for the working-area limits)."""
        xs = [setup.x_retract] + [cut["cut_x"] for cut in cuts]
        zs = [z for cut in cuts for z in (cut["z_from"], cut["z_to"])]
        return xs, zs
