"""The process allowance a program states (`; ALLOWANCE <mm> MM`, reference §B14): radial stock
its last cut leaves on purpose for shaving or grinding. The simulation then holds the last cut
to the root raised by it, neither shallower nor deeper; without the line the last cut reaches
the root itself (design notes §7)."""
from __future__ import annotations

import re

HEADER = re.compile(r";\s*ALLOWANCE\s+([0-9]+(?:\.[0-9]*)?)\s+MM\b.*")
DEPTH_TOLERANCE = 0.01   # mm


def header_allowance(line: str) -> float | None:
    match = HEADER.fullmatch(line)
    return float(match.group(1)) if match else None


def depth_problem(stock: float, allowance: float) -> str | None:
    """What is wrong with the stock the last cut leaves above the intended root, if anything."""
    if stock > allowance + DEPTH_TOLERANCE:
        wanted = "full depth (d_f2 + d_a0)/2" if not allowance else f"the allowance of {allowance:g} mm"
        return f"leaves {stock:.3f} mm above the intended root ({wanted} not reached)"
    if allowance and stock < allowance - DEPTH_TOLERANCE:   # below the root itself is a collision
        return f"leaves {stock:.3f} mm above the intended root, less than the stated allowance of {allowance:g} mm"
    return None
