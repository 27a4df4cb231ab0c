"""A move that turns the swivel A, or that runs before A (or, swivelled, Y) is written
(engine.simulation.hobbing.walk). The hob is not translated on
it, so the convexity the contacts' bounds rest on (engine.simulation.hobbing.contact_bounds) does
not hold, and its poses are followed at the final A only. The move is proved clear where no swivel
between its two ends can bring the hob near a solid, from two bounds that hold for every A:

* every point of the hob lies at X − r0 or farther from the work axis: the tip cylinder's points
  are centre + t·u + v·e_x + w·n with u and n in the Y-Z plane and v² + w² ≤ r0² (DIN, the
  swivel turns the hob about X), so their X is the centre's X ± r0 whatever A;
* and between Zc − e(A) and Zc + e(A) in height, Zc = Z + Y·sin A (the shift Y runs along the hob's
  axis, reference §A6), e(A) = r0·|cos A| + (L/2)·|sin A|. With a = |Y| + L/2 and b = r0, the
  reach a·|sin A| + b·|cos A| has period 180°; on 0…90° it is √(a² + b²)·sin(A + atan(b/a)),
  rising to its peak √(a² + b²) at A* = atan(a/b) and falling after; on 90…180° it is its mirror.
  So its largest value between two swivels is exact: the peak where ±A* + k·180° lies between
  them, else the larger of its values at the two ends.

A swivel that leaves both bounds open for some solid is refused (fail closed): an adversary turned
A from 1.763° to 80° with the hob 4 mm off the gear's tip in X and 36 mm above its face, and the
hob swept 3.24 mm into the finished gear while both ends were clear. Units mm and degrees."""
from __future__ import annotations

import math

from .contact_records import COLLISION_TOLERANCE
from .envelope import HobBody
from .solids import Solid

UNKNOWN = (-90.0, 90.0)    # the swivels an A not yet written may be at (a cylinder: modulo 180°)


def sweep_problem(solids: list[Solid], body: HobBody, tailstock: bool, start: dict, end: dict,
                  swivel_from: float | None, swivel_to: float, shift_travel: float) -> str | None:
    """Why the swivel from `swivel_from` (None: not known yet) to `swivel_to` over the move from
    `start` to `end` (DIN positions) cannot be proved clear, or None. A Y not yet written stands
    anywhere the last program left it: up to `shift_travel` (the machine's largest |Y|) either way."""
    ends = [position for position in (start, end) if {"X", "Z"} <= position.keys()]
    x_tip = min(position["X"] for position in ends) - body.radius
    heights = [position["Z"] for position in ends]
    shift = max((abs(position["Y"]) if "Y" in position else shift_travel for position in ends), default=0.0)
    reach = z_reach(body, shift, swivel_from, swivel_to)
    for solid in solids:
        if (solid.clamped_only and not tailstock) or x_tip >= solid.largest_radius + COLLISION_TOLERANCE:
            continue
        if max(heights) + reach >= solid.z_low and min(heights) - reach <= solid.z_high:
            return _refusal(solid, x_tip, swivel_from, swivel_to, "Y" not in end)
    return None


def unknown_pose(swivelling: bool, swivel_known: bool, swivel: float, end: dict) -> bool:
    """Whether a move must be proved for every swivel or shift the head may stand at: it turns A,
    or A is not written yet (the head stands where the last program left it; followed at 0 it
    passed a hob 1.94 mm inside the gear after a 20° helical's program: adversary 29), or Y is not
    written yet and the hob is swivelled (its centre then stands Y·sin A off in Z, reference §A6)."""
    return swivelling or not swivel_known or ("Y" not in end and swivel != 0.0)


def z_reach(body: HobBody, shift: float, swivel_from: float | None, swivel_to: float) -> float:
    """The most the hob reaches above or below its position's Z (mm) at any swivel between the two."""
    low, high = UNKNOWN if swivel_from is None else sorted((swivel_from, swivel_to))
    along, across = shift + body.half_length, body.radius
    if _peak_between(math.degrees(math.atan2(along, across)), low, high):
        return math.hypot(along, across)
    return max(_reach_at(body, shift, math.radians(low)), _reach_at(body, shift, math.radians(high)))


def _peak_between(peak: float, low: float, high: float) -> bool:
    """Whether ±peak + k·180° (degrees) lies between low and high for some whole k."""
    return any(math.floor((high - centre) / 180.0) >= math.ceil((low - centre) / 180.0) for centre in (peak, -peak))


def _reach_at(body: HobBody, shift: float, angle: float) -> float:
    sine, cosine = abs(math.sin(angle)), abs(math.cos(angle))
    return shift * sine + body.radius * cosine + body.half_length * sine


def _refusal(solid: Solid, x_tip: float, swivel_from: float | None, swivel_to: float, y_unknown: bool) -> str:
    if swivel_from is None:
        what = "the hob moves before A is written (the head may stand at any swivel the last program left)"
    elif swivel_from != swivel_to:
        what = f"the hob swivels from A{swivel_from:g}° to A{swivel_to:g}°"
    else:
        what = f"the hob moves at A{swivel_to:g}°"
    shift = " with Y not yet written (any shift the last program left)" if y_unknown else ""
    return (f"{what}{shift} with its tip cylinder {x_tip:.3f} mm from the work axis, within reach of {solid.name} "
            f"(radius {solid.largest_radius:.3f} mm): such a move is proved only where the hob clears the work in "
            "X or in Z for every swivel and shift it may have; write A and Y with the hob farther out")
