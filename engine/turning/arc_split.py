"""Arcs of more than 180° split in two: a program states an arc by its end point and radius
(ISO `R`, 840D `CR=`), and a positive radius means the arc of at most 180° (the longer one
would need a negative radius, which not every control reads the same way). Two halves are
unambiguous on every control."""
from __future__ import annotations

import math
from dataclasses import replace

from .moves import Move

ARC_KINDS = ("cw", "ccw")
# Sweeps up to this much over 180° (rad) are a half circle drawn with rounding.
HALF_TURN_NOISE = 1e-9


def with_short_arcs(moves: list[Move]) -> list[Move]:
    """The moves with every arc over 180° replaced by its two halves."""
    result: list[Move] = []
    for move in moves:
        if move.kind in ARC_KINDS and result:
            result.extend(halves(result[-1], move))
        else:
            result.append(move)
    return result


def halves(previous: Move, arc: Move) -> list[Move]:
    """[arc] or its two halves; X is a diameter, i the radial centre offset as a radius."""
    start_z, start_r = previous.z, previous.x / 2.0
    centre_z, centre_r = start_z + arc.k, start_r + arc.i
    a0 = math.atan2(start_r - centre_r, start_z - centre_z)
    a1 = math.atan2(arc.x / 2.0 - centre_r, arc.z - centre_z)
    sense = 1.0 if arc.kind == "ccw" else -1.0
    sweep = (sense * (a1 - a0)) % (2.0 * math.pi)
    if sweep <= math.pi + HALF_TURN_NOISE:
        return [arc]
    middle = a0 + sense * sweep / 2.0
    radius = math.hypot(start_z - centre_z, start_r - centre_r)
    mid_z, mid_r = centre_z + radius * math.cos(middle), centre_r + radius * math.sin(middle)
    first = replace(arc, z=mid_z, x=2.0 * mid_r)
    second = replace(arc, i=centre_r - mid_r, k=centre_z - mid_z)
    return [first, second]
