"""Lathe arcs (G2/G3 with a radius, X a diameter): the radius must reach from one end to the
other, and the points of the arc farthest along Z and X must lie within the travel too, not
only its end points."""
from __future__ import annotations

import math

from .refusals import Refused

Point = tuple[float, float]   # (z, r) in mm

# mm by which half the chord may exceed the radius: the rounding of end points and radius to
# three decimals moves them by less; a control alarms (or, worse, guesses a centre) beyond its own.
ARC_TOLERANCE = 0.002


def check_radius(start_x: float, start_z: float, end_x: float, end_z: float, radius: float) -> None:
    """No circle of radius |R| passes through both ends if |R| is shorter than half the chord."""
    half_chord = math.hypot((end_x - start_x) / 2.0, end_z - start_z) / 2.0
    if abs(radius) + ARC_TOLERANCE < half_chord:
        raise Refused(f"the arc's radius {abs(radius):g} is shorter than half its chord ({half_chord:.3f}): "
                      "no circle of that radius passes through both ends")


def arc_extremes(start: Point, end: Point, radius: float, ccw: bool) -> list[Point]:
    """The end points and the quadrant points the arc passes, in (z, r). ccw is G3 with Z to the
    right and the radius up; R > 0 the arc up to 180°, R < 0 the longer one."""
    centre = arc_centre(start, end, radius, ccw)
    size = abs(radius)
    a0, a1 = (math.atan2(p[1] - centre[1], p[0] - centre[0]) for p in (start, end))
    sweep = (a1 - a0) % math.tau if ccw else (a0 - a1) % math.tau
    points = [start, end]
    for quadrant in range(4):
        angle = quadrant * math.pi / 2
        turned = (angle - a0) % math.tau if ccw else (a0 - angle) % math.tau
        if turned <= sweep:
            points.append((centre[0] + size * math.cos(angle), centre[1] + size * math.sin(angle)))
    return points


def arc_centre(start: Point, end: Point, radius: float, ccw: bool) -> Point:
    dz, dr = end[0] - start[0], end[1] - start[1]
    chord = math.hypot(dz, dr)
    if chord == 0:
        return start
    rise = math.sqrt(max(radius * radius - chord * chord / 4.0, 0.0))
    side = 1.0 if ccw == (radius > 0) else -1.0      # the centre lies left of a short ccw arc
    return ((start[0] + end[0]) / 2.0 - side * rise * dr / chord,
            (start[1] + end[1]) / 2.0 + side * rise * dz / chord)


def arc_box(start_x: float, start_z: float, end_x: float, end_z: float, radius: float,
            ccw: bool) -> dict[str, tuple[float, float]]:
    """{axis: (lowest, highest)} the arc reaches, X as a diameter."""
    points = arc_extremes((start_z, start_x / 2.0), (end_z, end_x / 2.0), radius, ccw)
    zs, rs = [z for z, _ in points], [r for _, r in points]
    return {"Z": (round(min(zs), 6), round(max(zs), 6)), "X": (round(2 * min(rs), 6), round(2 * max(rs), 6))}
