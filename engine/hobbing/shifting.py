"""Hob shifting along Y (reference §B15): a fixed position for this part, or a step per part
that walks the generating zone along the hob and wraps at the end of the usable length."""
from __future__ import annotations

import math

from ..errors import EngineError
from ..gears.hob_geometry import generating_length, lead_angle
from .choices import Choices

SHIFT_MARGIN = 5.0          # mm kept free at each end of the hob
PITCH_MULTIPLE_TOLERANCE = 0.05   # mm: a step this close to n axial pitches repeats the same teeth


def travel_needed(choices: Choices) -> float:
    """Hob length needed beyond the generating zone and margins: twice a fixed offset from
    the hob centre, or at least one step when shifting per part."""
    if choices.shift_per_part:
        return choices.shift_per_part
    return 2 * abs(choices.shift_y)


def parameters(choices: Choices, hob, gear) -> dict:
    """shift_on, shift_y (fixed position), shift_per_part and the range shift_min…shift_max."""
    if not choices.shifting:
        return {"shift_on": False, "shift_y": 0.0, "shift_per_part": 0.0, "shift_min": 0.0, "shift_max": 0.0}
    if not choices.shift_per_part:
        return {"shift_on": True, "shift_y": choices.shift_y, "shift_per_part": 0.0,
                "shift_min": choices.shift_y, "shift_max": choices.shift_y}
    half = usable_length(hob, gear) / 2
    _check_step(choices.shift_per_part, half, hob, gear)
    return {"shift_on": True, "shift_y": 0.0, "shift_per_part": choices.shift_per_part,
            "shift_min": round(-half, 3), "shift_max": round(half, 3)}


def usable_length(hob, gear) -> float:
    """L_s = L_hob − L_gen − margins (§B15)."""
    return hob.length - generating_length(gear.module, gear.pressure_angle) - 2 * SHIFT_MARGIN


def axial_pitch(module: float, lead_angle: float) -> float:
    """π·m_n/cos γ (§B15)."""
    return math.pi * module / math.cos(math.radians(lead_angle))


def _check_step(step: float, half: float, hob, gear) -> None:
    if step > 2 * half:
        raise EngineError(f"gear {gear.id}: shift per part {step:g} mm exceeds the usable shift length "
                          f"{max(0.0, 2 * half):.1f} mm of hob {hob.id} (length {hob.length:g}); "
                          f"use a smaller step or a longer hob")
    pitch = axial_pitch(gear.module, lead_angle(hob.module, hob.starts, hob.tip_diameter))
    multiple = round(step / pitch)
    if multiple >= 1 and abs(step - multiple * pitch) < PITCH_MULTIPLE_TOLERANCE:
        raise EngineError(f"gear {gear.id}: shift per part {step:g} mm is {multiple} axial pitch(es) of the "
                          f"hob ({pitch:.3f} mm), so every part would meet the same hob teeth; choose another step")


def y_positions(shift: dict) -> list[float]:
    return [0.0, shift["shift_min"], shift["shift_max"]]
