"""The cutting speeds of the reference's table (docs/reference/hobbing.md §C, typical practice
[K][?], calibrate before use): v [m/min] by workpiece material and by the hob's material and
coating. The rows are data, table material (engine.gears.materials loads them onto the gear
record, Gear.cutting_speeds); the four rows of §C are kept here as well for a gear record made
without the database (the migration seeds the same numbers, tests/test_materials.py checks).
The planner bounds the speed it takes from the history by the upper end
(engine.gears.case_base), and the simulation holds every commanded hob speed to the range
(engine.simulation.hobbing.cutting_speed)."""
from __future__ import annotations

import math

from .records import CuttingSpeeds, Gear, Hob

TOOLS = ("uncoated HSS", "coated HSS", "carbide")


# §C: workpiece material -> (uncoated HSS wet, TiN/TiAlN coated PM-HSS, carbide dry), m/min, and
# the no-history defaults (uncoated, coated); the seed rows of table material.
SPEEDS = {
    "45": CuttingSpeeds(((30.0, 45.0), (60.0, 120.0), (150.0, 300.0)), (38.0, 90.0)),
    "C45": CuttingSpeeds(((30.0, 45.0), (60.0, 120.0), (150.0, 300.0)), (38.0, 90.0)),
    "20CrMnTi": CuttingSpeeds(((30.0, 40.0), (60.0, 110.0), (150.0, 280.0)), (35.0, 85.0)),
    "40Cr": CuttingSpeeds(((20.0, 35.0), (50.0, 90.0), (120.0, 220.0)), (28.0, 70.0)),
}
# A gear with no material stated: the widest range of the hob's column over the four rows of §C
# (lowest lower end to highest upper end), as before materials were data.
UNSTATED = tuple((min(row.ranges[column][0] for row in SPEEDS.values()),
                  max(row.ranges[column][1] for row in SPEEDS.values())) for column in range(len(TOOLS)))


def tool_of(hob: Hob) -> int:
    """The §C column of a hob record: carbide by its material, else coated HSS when it has a
    coating (any: the table's column is TiN/TiAlN), else uncoated HSS."""
    if "carbide" in hob.material.casefold():
        return 2
    return 1 if hob.coating.strip() else 0


def speeds_of(gear: Gear) -> CuttingSpeeds | None:
    """The gear's row: the one loaded from table material, else (a record made without the
    database) the seed row of its material; None for a material neither lists, or none."""
    if gear.cutting_speeds is not None:
        return gear.cutting_speeds
    wanted = (gear.material or "").strip().casefold()
    return next((row for name, row in SPEEDS.items() if name.casefold() == wanted), None)


def speed_range(gear: Gear, hob: Hob) -> tuple[float, float, bool]:
    """(lowest, highest v, listed): the row of the gear's material; no row (no material stated:
    an unknown one is refused at instantiate) takes the widest range of the hob's column."""
    column = tool_of(hob)
    row = speeds_of(gear)
    if row is not None:
        return (*row.ranges[column], True)
    return (*UNSTATED[column], False)


def most_hob_speed(gear: Gear, hob: Hob) -> int:
    """The highest whole n0 [r/min] within the upper end: n0 ≤ 1000·v/(π·d_a0) (§B4)."""
    return math.floor(1000 * speed_range(gear, hob)[1] / (math.pi * hob.tip_diameter) + 1e-9)
