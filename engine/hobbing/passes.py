"""The cuts of a hobbing job and where each axial pass starts and ends (reference §B3,
§B7, §B8, §B13, §B14). Z = 0 is the workpiece's top face, the blank lies below it."""
from __future__ import annotations

import msgspec

from ..gears.cutting_data import CuttingData, per_minute, programmed_feed
from . import geometry
from .choices import Choices

APPROACH_SAFETY = 2.0     # mm added to the run-in E (§B7: 1–3 mm)
LIMIT_MARGIN = 1.0        # mm between the outermost move and the working-area limit
CUT_NAMES = {1: "ROUGH", 2: "FINISH"}


class Reach(msgspec.Struct, frozen=True):
    """How far the hob reaches along Z from its centre when cutting at full depth: the run-in
    E before the face it enters and the run-out U beyond the face it leaves."""
    approach: float
    overrun: float


class Cut(msgspec.Struct, frozen=True):
    """One cut of a job (rough or finish): its centre distance and pass direction."""
    number: int               # 1 = rough, 2 = finish (a single cut is number 2, named SINGLE)
    name: str
    centre_distance: float
    on: bool
    climb: bool


def hob_reach(gear, hob_tip_diameter: float, swivel: float, full_depth: float) -> Reach:
    depth = geometry.cut_depth(gear.tip_diameter, hob_tip_diameter, full_depth)
    approach = geometry.approach_length(depth, hob_tip_diameter, gear.tip_diameter, swivel)
    overrun = geometry.overrun_length(gear.module, depth, gear.pressure_angle, swivel)
    return Reach(approach + APPROACH_SAFETY, overrun)


def plan_cuts(module: float, full_depth: float, choices: Choices) -> list[Cut]:
    """Rough (off for a single cut) and finish; the rough cut leaves the finishing stock. The final
    cut stops short of full depth by the job's process allowance, left for shaving or grinding
    (§B14: "before shaving or grinding, add the process allowance at the final pass")."""
    count = choices.cut_count(module)
    final = full_depth + choices.allowance
    rough = final + choices.stock(module)
    return [Cut(1, CUT_NAMES[1], rough, count == 2, choices.climb(1, count)),
            Cut(2, CUT_NAMES[2] if count == 2 else "SINGLE", final, True, choices.climb(2, count))]


def pass_ends(reach: Reach, face_top: float, face_bottom: float, climb: bool) -> tuple[float, float]:
    """(z_from, z_to) of an axial pass across the faces: climb enters above the top face and
    leaves below the bottom one; conventional the reverse. The hob infeeds at z_from, clear
    of the blank by the run-in E."""
    if climb:
        return face_top + reach.approach, face_bottom - reach.overrun
    return face_bottom - reach.approach, face_top + reach.overrun


def feeds(cut: Cut, cutting: CuttingData, starts: int, teeth: int) -> dict:
    """Feeds of one cut in mm/min (G94): rough cuts at the roughing feed, finishing at the
    finishing feed, a single cut at the roughing feed."""
    axial = cutting.axial_feed_finish if cut.name == "FINISH" else cutting.axial_feed_rough
    return {"feed_axial": programmed_feed(per_minute(axial, cutting.hob_speed, starts, teeth)),
            "feed_radial": programmed_feed(per_minute(cutting.radial_feed, cutting.hob_speed, starts, teeth))}


def working_area(xs, ys, zs) -> dict:
    """G25/G26 limits enclosing every position the program moves to, with a margin."""
    def bounds(axis, values):
        return {f"{axis}_lower": round(min(values) - LIMIT_MARGIN, 3),
                f"{axis}_upper": round(max(values) + LIMIT_MARGIN, 3)}
    return {**bounds("x", xs), **bounds("y", ys), **bounds("z", zs)}
