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


def clearance_to_cone(hob_radius: float, half_length: float, swivel: float, centre: tuple,
                      blank: tuple) -> float:
    """Least distance (conservative) between the hob envelope, centre (X, Z), and a conical
    blank `blank` = (tip radius at Z = 0, radius change per mm of Z, face width), the blank
    over Z −b…0. With Z scaled by cos η the hob's section is a circle of r0 whose centre runs
    over a vertical segment of half-length y_max·sin η (the points off the Y = 0 plane, §B7);
    the blank's meridian is a trapezoid, taken whole at every y. Scaling Z by cos η ≤ 1 only
    shortens distances. Negative: the hob reaches into the blank."""
    (x, z), (radius, slope, width) = centre, blank
    eta = math.radians(abs(swivel))
    widest = max(radius, radius - width * slope)
    if x - hob_radius >= widest:
        return x - hob_radius - widest
    y_max = min(math.sqrt(widest ** 2 - max(x - hob_radius, 0.0) ** 2),
                half_length * math.cos(eta) + hob_radius * math.sin(eta))
    half = y_max * math.sin(eta)
    scaled_z = z * math.cos(eta)
    trapezoid = [(0.0, 0.0), (radius, 0.0), (radius - width * slope, -width * math.cos(eta)),
                 (0.0, -width * math.cos(eta))]
    return _segment_to_polygon((x, scaled_z - half), (x, scaled_z + half), trapezoid) - hob_radius


def _segment_to_polygon(start: tuple, end: tuple, polygon: list) -> float:
    """Distance between a segment and a convex polygon (0 where they meet)."""
    if _inside(start, polygon) or _inside(end, polygon):
        return 0.0
    edges = list(zip(polygon, polygon[1:] + polygon[:1]))
    return min(_segments(start, end, a, b) for a, b in edges)


def _inside(point: tuple, polygon: list) -> bool:
    sides = [_cross(a, b, point) for a, b in zip(polygon, polygon[1:] + polygon[:1])]
    return all(side >= 0 for side in sides) or all(side <= 0 for side in sides)


def _cross(a: tuple, b: tuple, p: tuple) -> float:
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])


def _segments(p1: tuple, p2: tuple, q1: tuple, q2: tuple) -> float:
    """Distance between two segments: 0 if they cross, else the least endpoint-to-segment one."""
    d1, d2, d3, d4 = _cross(q1, q2, p1), _cross(q1, q2, p2), _cross(p1, p2, q1), _cross(p1, p2, q2)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return 0.0
    return min(_point_to_segment(p1, q1, q2), _point_to_segment(p2, q1, q2),
               _point_to_segment(q1, p1, p2), _point_to_segment(q2, p1, p2))


def _point_to_segment(p: tuple, a: tuple, b: tuple) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = dx * dx + dy * dy
    t = 0.0 if length == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length))
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)
