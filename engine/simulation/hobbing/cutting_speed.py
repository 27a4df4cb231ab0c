"""The cutting speed a commanded hob speed gives, held to the reference's table (reference §B4,
§C; the table is engine.gears.speed_table): v = π·d_a0·n0/1000 m/min for every S the program
commands, within the row of the gear's material and the column of the hob's material and coating.

§C is typical practice [K][?] (calibrate before use). Above its upper end the hob wears and
burns and the flanks tear: refused. Below its lower end the cut is only slower than practice: a
note, not a refusal (the shop's own history, engine/gears/cases.py, may run slower than the
table). The rows are table material's (the gear record carries its material's). A gear with no
material stated is held to the widest range of the hob's column over the four rows of §C, the
lowest lower end to the highest upper end, with a note saying so (one whose material the table
lacks is refused at instantiate, engine.programs.instantiate.check_material)."""
from __future__ import annotations

import math

from ...gears.records import Gear, Hob
from ...gears.speed_table import TOOLS, speed_range, tool_of

RELATIVE_TOLERANCE = 1e-6     # a speed at the table's end is within it


def cutting_speed(tip_diameter: float, spindle_speed: float) -> float:
    """v = π·d_a0·n0/1000 [m/min] (§B4)."""
    return math.pi * tip_diameter * spindle_speed / 1000


def material_note(gear: Gear, hob: Hob) -> str | None:
    low, high, listed = speed_range(gear, hob)
    if listed:
        return None
    said = f"material {gear.material}" if gear.material else "no material"
    return (f"gear {gear.id} has {said}, which §C does not list: the {TOOLS[tool_of(hob)]} hob's speed is held "
            f"to the widest range of the table, {low:g}–{high:g} m/min")


def speed_problem(speed: float, gear: Gear, hob: Hob) -> tuple[str, bool] | None:
    """(message, refuses) for the hob speed S [r/min], or None when it is within §C."""
    v = cutting_speed(hob.tip_diameter, speed)
    low, high, _ = speed_range(gear, hob)
    what = (f"S{speed:g} on hob {hob.id} (d_a0 {hob.tip_diameter:g} mm) cuts at v = π·d_a0·n0/1000 = "
            f"{v:.1f} m/min")
    where = f"{TOOLS[tool_of(hob)]} on {gear.material or 'an unlisted material'}"
    if v > high * (1 + RELATIVE_TOLERANCE):
        return f"{what}, above the {high:g} m/min §C allows for {where} (range {low:g}–{high:g})", True
    if v < low * (1 - RELATIVE_TOLERANCE):
        return f"{what}, below the {low:g}–{high:g} m/min of §C for {where}: slower than practice", False
    return None
