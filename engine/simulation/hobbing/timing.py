"""The cycle time (the definition the models print in the header, docs/design.md §7): over the
blocks in order, a G1 takes √(ΔX²+ΔY²+ΔZ²)/F (G94, mm/min), a G0 max(|ΔX|,|ΔY|,|ΔZ|)/rapid
rate (each axis at the rapid rate), a dwell s seconds (`G4 F<s>`; Fanuc `G04 X<s>`, `G04 P<1000·s>`);
rotary-only and non-motion blocks nothing. Program values: the program starts at the machine's
load position where the record has one; an axis whose start is unknown moves from wherever its
first block puts it (no travel).
A header `; CYCLE TIME <m> MIN` more than HEADER_TOLERANCE off the simulated time refuses."""
from __future__ import annotations

import math
import re

HEADER = re.compile(r";\s*CYCLE TIME\s+([0-9]+(?:\.[0-9]*)?)\s+MIN\s*")
RELATIVE_TOLERANCE, ABSOLUTE_TOLERANCE = 0.02, 0.1      # 2 % + 0.1 min


def rapid_minutes(start: dict, end: dict, rapid_rate: float) -> float:
    return max((abs(end[axis] - start.get(axis, end[axis])) for axis in end), default=0.0) / rapid_rate


def feed_minutes(start: dict, end: dict, feed: float) -> float:
    return math.sqrt(sum((end[axis] - start.get(axis, end[axis])) ** 2 for axis in end)) / feed


def header_minutes(line: str) -> float | None:
    match = HEADER.fullmatch(line)
    return float(match.group(1)) if match else None


def header_problem(header: float, simulated: float) -> str | None:
    allowed = RELATIVE_TOLERANCE * simulated + ABSOLUTE_TOLERANCE
    if abs(header - simulated) <= allowed:
        return None
    return (f"the header says a cycle time of {header:g} min, the simulation takes {simulated:.2f} min "
            f"(more than 2 % + 0.1 min apart)")
