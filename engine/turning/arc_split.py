"""Arcs of more than MAX_ARC_SWEEP split into equal pieces: a program states an arc by its end
point and radius (ISO `R`, 840D `CR=`). A positive radius means the arc of at most 180°, and
near 180° the centre found from the printed (rounded) end points and radius is ill
conditioned: a chord of 10.0007 mm printed with R5.000 has no centre at all. Pieces of at
most 120° keep the half chord well below the radius, so the rounding moves the centre by
about the rounding itself."""
from __future__ import annotations

import math

from msgspec.structs import replace

from .moves import Move

ARC_KINDS = ("cw", "ccw")
MAX_ARC_SWEEP = math.radians(120.0)
# Sweeps up to this much over the largest (rad) are that sweep drawn with rounding.
SWEEP_NOISE = 1e-9


def with_short_arcs(moves: list[Move]) -> list[Move]:
    """The moves with every arc over MAX_ARC_SWEEP replaced by equal pieces."""
    result: list[Move] = []
    for move in moves:
        if move.kind in ARC_KINDS and result:
            result.extend(pieces(result[-1], move))
        else:
            result.append(move)
    return result


def pieces(previous: Move, arc: Move) -> list[Move]:
    """[arc] or its equal pieces; X is a diameter, i the radial centre offset as a radius."""
    assert arc.i is not None and arc.k is not None   # an arc move has its centre
    start_z, start_r = previous.z, previous.x / 2.0
    centre_z, centre_r = start_z + arc.k, start_r + arc.i
    a0 = math.atan2(start_r - centre_r, start_z - centre_z)
    a1 = math.atan2(arc.x / 2.0 - centre_r, arc.z - centre_z)
    sense = 1.0 if arc.kind == "ccw" else -1.0
    sweep = (sense * (a1 - a0)) % (2.0 * math.pi)
    count = math.ceil(sweep / MAX_ARC_SWEEP - SWEEP_NOISE)
    if count <= 1:
        return [arc]
    radius = math.hypot(start_z - centre_z, start_r - centre_r)
    found, here = [], (start_z, start_r)
    for n in range(1, count):
        angle = a0 + sense * sweep * n / count
        end = (centre_z + radius * math.cos(angle), centre_r + radius * math.sin(angle))
        found.append(replace(arc, z=end[0], x=2.0 * end[1], i=centre_r - here[1], k=centre_z - here[0]))
        here = end
    found.append(replace(arc, i=centre_r - here[1], k=centre_z - here[0]))
    return found
