"""The cutting speeds of the reference's table (docs/reference/hobbing.md §C, typical practice
[K][?], calibrate before use): v [m/min] by workpiece material and by the hob's material and
coating. The planner bounds the speed it takes from the history by the upper end
(engine.gears.case_base), and the simulation holds every commanded hob speed to the range
(engine.simulation.hobbing.cutting_speed)."""
from __future__ import annotations

import math

from .records import Gear, Hob

TOOLS = ("uncoated HSS", "coated HSS", "carbide")
# §C: workpiece material -> (uncoated HSS wet, TiN/TiAlN coated PM-HSS, carbide dry), m/min.
SPEEDS = {
    "45": ((30.0, 45.0), (60.0, 120.0), (150.0, 300.0)),
    "C45": ((30.0, 45.0), (60.0, 120.0), (150.0, 300.0)),
    "20CrMnTi": ((30.0, 40.0), (60.0, 110.0), (150.0, 280.0)),
    "40Cr": ((20.0, 35.0), (50.0, 90.0), (120.0, 220.0)),
}


def tool_of(hob: Hob) -> int:
    """The §C column of a hob record: carbide by its material, else coated HSS when it has a
    coating (any: the table's column is TiN/TiAlN), else uncoated HSS."""
    if "carbide" in hob.material.casefold():
        return 2
    return 1 if hob.coating.strip() else 0


def speed_range(gear: Gear, hob: Hob) -> tuple[float, float, bool]:
    """(lowest, highest v, listed): the row of the gear's material; a material §C does not list,
    or none, takes the widest range of the hob's column (lowest lower end to highest upper end)."""
    column = tool_of(hob)
    wanted = (gear.material or "").strip().casefold()
    for material, row in SPEEDS.items():
        if material.casefold() == wanted:
            return (*row[column], True)
    return (min(row[column][0] for row in SPEEDS.values()), max(row[column][1] for row in SPEEDS.values()), False)


def most_hob_speed(gear: Gear, hob: Hob) -> int:
    """The highest whole n0 [r/min] within the upper end: n0 ≤ 1000·v/(π·d_a0) (§B4)."""
    return math.floor(1000 * speed_range(gear, hob)[1] / (math.pi * hob.tip_diameter) + 1e-9)
