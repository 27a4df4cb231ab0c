"""The feed marks a program's last cut leaves, held to the depth the gear's quality grade allows
(reference §B6, issue 29; the table is engine.gears.feed_marks).

From the program alone: the walk measures each cut's feed along its axial pass per workpiece
revolution (its F word over the table speed |k_B|·S the coupling gives), the marks are
δ = f²·sin α_n/(4·d_a0) with the gear's α_n and the hob record's d_a0, and the last cut of each
toothing must leave them no deeper than its grade allows (a share of ISO 1328-1's helix form
tolerance f_fβ for that toothing's reference diameter and face width). Earlier cuts are cut
again by the last one. A program stating a process allowance (`; ALLOWANCE <mm> MM`) leaves
stock for shaving or grinding, which takes the marks with it: not held. A cut without an axial
pass (a worm wheel's plunge or tangential feed) leaves no axial feed marks: not held.

Each function yields (step, message, refuses)."""
from __future__ import annotations

from ...gears.feed_marks import allowed_depth, grade_of, mark_depth, mark_share, toothings
from ...gears.records import Gear, Hob
from .allowance import header_allowance

RELATIVE_TOLERANCE = 1e-6   # marks at the limit are within it


def mark_facts(steps, gear: Gear, hob: Hob, report):
    if any(header_allowance(step.line) for step in steps if step.kind == "comment"):
        return
    last = {cut.unit: cut for cut in report.cuts}            # in the order the walk closed them
    limits = {name: allowed_depth(gear.quality_grade, d, b) for name, d, b in toothings(gear)}
    for unit, cut in last.items():
        if cut.mark_feed is None or unit not in limits:
            continue
        depth = mark_depth(cut.mark_feed, gear.pressure_angle, hob.tip_diameter)
        if depth > limits[unit] * (1 + RELATIVE_TOLERANCE):
            yield _step(steps, cut.number), _message(cut, unit, depth, limits[unit], gear, hob), True


def _step(steps, number: int):
    """The cut's first block that writes Z (its axial pass), else the cut's first line."""
    after = [step for step in steps if step.number >= number]
    return next((step for step in after if step.kind == "block" and "Z" in step.item.values),
                after[0] if after else steps[0])


def _message(cut, unit: str, depth: float, limit: float, gear: Gear, hob: Hob) -> str:
    grade = gear.quality_grade if gear.quality_grade is not None else f"unstated ({grade_of(None)})"
    share = mark_share(grade_of(gear.quality_grade))
    return (f"the last cut of {unit} feeds {cut.mark_feed:.3f} mm per workpiece revolution: its feed marks "
            f"f²·sin α_n/(4·d_a0) = {depth * 1000:.1f} µm (α_n {gear.pressure_angle:g}°, hob {hob.id} d_a0 "
            f"{hob.tip_diameter:g} mm) are deeper than the {limit * 1000:.1f} µm grade {grade} allows ({share:g} of "
            "the helix form tolerance f_fβ, ISO 1328-1; reference §B6): lower the last cut's feed")
