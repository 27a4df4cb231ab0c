"""The header's `; FLOOR TO FLOOR <min> MIN` held to the program text and the machine record
(issue 29, reference §B16): the simulated cycle time plus, at the record's stated times, the
swivel (|ΔA| over the A words from the head's 0°, at swivel_speed °/s), a run-up per M3/M4, a
synchronisation per EGON, the tailstock per M20 and per M21, the door per its close and open M
codes, a tool call per T word, and loading and unloading once. Counted from what the program
says, never from the job that made it. A line stated for a machine that does not state all these
times, a second line, a line after the first motion, or a line off by more than TOLERANCE is refused."""
from __future__ import annotations

import re

from ...machines.records import FLOOR_TIMES, Machine, unstated_floor_times
from .coupling import COUPLING_ON
from .headers import header_place_problem
from .report import Report

HEADER = re.compile(r"; FLOOR TO FLOOR ([0-9]+(?:\.[0-9]+)?) MIN")
# min: the header's own rounding to 0.1 min, and 0.01 min (0.6 s) for the cycle time of a program
# that shifts per part (followed at the low end of its R11 interval). The handling is a count, exact
# on both sides: the cycle time's 2 % + 0.1 min let an uncounted spindle start and tailstock clamp
# (5 s) through (adversary 29).
TOLERANCE = 0.06
SPINDLE_STARTS, TAILSTOCK = frozenset({3, 4}), frozenset({20, 21})


def floor_facts(steps: list, machine: Machine, report: Report):
    """(step, problem, refuses) of the program's floor-to-floor line, if it states one."""
    stated = [(step, float(match.group(1))) for step in steps
              if step.kind == "comment" and (match := HEADER.fullmatch(step.line))]
    if not stated:
        return
    step, minutes = stated[0]
    for again, _ in stated[1:]:
        yield again, "a second `; FLOOR TO FLOOR` line: the header states it once", True
    first_motion = next((s.number for s in steps if s.kind == "block" and s.item.moves), None)
    if first_motion is not None and step.number > first_motion:
        yield step, header_place_problem("FLOOR TO FLOOR", False, True), True
    missing = unstated_floor_times(machine)
    if missing:
        yield step, (f"machine {machine.name} does not state {', '.join(missing)}: a floor-to-floor time cannot "
                     "be proved for it; state them on the machine record or leave the line out"), True
        return
    simulated = report.cycle_time + handling_seconds(steps, machine) / 60
    if abs(minutes - simulated) > TOLERANCE:
        yield step, (f"the header says a floor-to-floor time of {minutes:g} min; the program takes {simulated:.2f} "
                     f"min (cycle {report.cycle_time:.2f} min plus swivel, spindle, synchronisation, tailstock, "
                     "door, tool and loading at the machine record's times)"), True


def handling_seconds(steps: list, machine: Machine) -> float:
    """Seconds the program spends besides its motion, at the machine record's times (all stated)."""
    swivel, at = 0.0, 0.0
    counts = {"spindle": 0, "sync": 0, "tailstock": 0, "door": 0, "tool": 0}
    doors = {code for code in (machine.door_close_m, machine.door_open_m) if code}
    for step in steps:
        if step.kind == "statement" and step.item.name in COUPLING_ON:
            counts["sync"] += 1
        if step.kind != "block":
            continue
        if "A" in step.item.values:
            swivel, at = swivel + abs(step.item.values["A"] - at), step.item.values["A"]
        counts["spindle"] += len(step.m_codes & SPINDLE_STARTS)
        counts["tailstock"] += len(step.m_codes & TAILSTOCK)
        counts["door"] += len(step.m_codes & doors)
        counts["tool"] += "T" in step.item.values
    speed, runup, sync, tailstock, door, tool, load = (float(getattr(machine, name) or 0.0) for name in FLOOR_TIMES)
    return (swivel / speed + counts["spindle"] * runup + counts["sync"] * sync + counts["tailstock"] * tailstock
            + counts["door"] * door + counts["tool"] * tool + load)
