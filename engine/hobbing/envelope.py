"""How far the hob's envelope reaches along Z from its centre (reference §B7, design notes §7).

The hob is a cylinder of tip radius r0 = d_a0/2 and length L whose axis lies in the Y–Z plane,
swivelled by η about X. Its points are (x + c, y, Z + y·tan η + s/cos η) with c² + s² ≤ r0²
(c along X, s across the axis in the Y–Z plane) and |y| ≤ l·cos η + r0·sin|η|, l the hob's
extent along its axis from the contact point either way (L/2 plus the largest shift). Bounding
the y·tan η term and the s/cos η term each by its own maximum overstates the reach a little: the
conservative side, the same as §B7's tan η·√(h(d_a2 − h)) term."""
from __future__ import annotations

import math


def half_length(hob_length: float, shift: dict) -> float:
    """How far the hob extends along its axis from the contact point: half its length plus the
    largest shift the program makes (shifting.parameters)."""
    return hob_length / 2 + max(abs(shift["shift_min"]), abs(shift["shift_max"]), abs(shift["shift_y"]))


def reach_into_cylinder(hob_radius: float, half_length: float, swivel: float, centre_x: float,
                        radius: float) -> float | None:
    """Half-length along Z of the part of the hob envelope, centre at X = centre_x, that lies
    within `radius` of the work axis; None when the hob stays radially outside that cylinder."""
    overlap = radius - (centre_x - hob_radius)
    if overlap <= 0:
        return None
    eta = math.radians(abs(swivel))
    across = hob_radius if centre_x <= radius else math.sqrt(hob_radius ** 2 - (centre_x - radius) ** 2)
    along = radius if centre_x <= hob_radius else math.sqrt(radius ** 2 - (centre_x - hob_radius) ** 2)
    along = min(along, half_length * math.cos(eta) + hob_radius * math.sin(eta))
    return across / math.cos(eta) + along * math.tan(eta)
