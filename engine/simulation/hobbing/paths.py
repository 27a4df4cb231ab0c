"""The hob positions along a move, at most POSE_STEP apart. A G1 runs on the straight line. A G0
runs on it too where the control interpolates rapids (840D RTLION), but each axis at its own
rapid rate where it does not (RTLIOF, the cycle time's model): all axes at the same speed until
the shortest arrives, a dog-leg. Which one a machine does is its setting, so both are followed."""
from __future__ import annotations

import math

POSE_STEP = 0.5          # mm
AXES = ("X", "Y", "Z")


def move_poses(start: dict, end: dict, rapid: bool) -> tuple:
    """(x, y, z) lists of DIN positions from start to end (an axis whose start is unknown
    jumps: only the end is followed)."""
    return pieces_poses(move_pieces(start, end, rapid))


def move_pieces(start: dict, end: dict, rapid: bool) -> list[tuple[dict, dict]]:
    """The straight pieces (from, to) the hob follows: the line, and for a rapid the dog-leg."""
    begin = {axis: start.get(axis, end[axis]) for axis in end} if {"X", "Z"} <= start.keys() else dict(end)
    pieces = [(begin, end)]
    leg = _dog_leg(begin, end) if rapid else []
    if len(leg) > 2:   # with one arrival (one axis moving, or all by the same) the leg is the line itself
        pieces += list(zip(leg[:-1], leg[1:]))
    return pieces


def pieces_poses(pieces: list[tuple[dict, dict]]) -> tuple:
    """(x, y, z) lists of the poses along the pieces, POSE_STEP apart at most."""
    lines = [_line(a, b) for a, b in pieces]
    return tuple([value for line in lines for value in line[i]] for i in range(3))


def corners(pieces: list[tuple[dict, dict]]) -> tuple[list[float], list[float], list[float]]:
    """(x, y, z) lists of the pieces' ends: every pose lies between their least and greatest."""
    ends = [point for piece in pieces for point in piece]
    x, y, z = ([point.get(axis, 0.0) for point in ends] for axis in AXES)
    return x, y, z


def pose_count(a: dict, b: dict) -> int:
    """Poses on the piece from a to b, both ends included."""
    length = math.dist([a.get(axis, 0.0) for axis in AXES], [b.get(axis, 0.0) for axis in AXES])
    return max(2, int(math.ceil(length / POSE_STEP)) + 1)


def _dog_leg(begin: dict, end: dict) -> list[dict]:
    """begin, the points where each axis arrives (all moving at one speed), end. With a single
    arrival (one axis moving, or every moving axis travelling the same distance) that is
    [begin, end]: the straight line, whose poses move_poses already has, so it is not followed
    twice (the same poses give the same contacts)."""
    travel = {axis: end[axis] - begin[axis] for axis in end}
    arrivals = sorted({abs(d) for d in travel.values() if d})
    points = [dict(begin)]
    for reached in arrivals:
        points.append({axis: begin[axis] + math.copysign(min(abs(d), reached), d) for axis, d in travel.items()})
    return points


def _line(a: dict, b: dict) -> tuple:
    count = pose_count(a, b)
    shares = [i / (count - 1) for i in range(count)]
    return tuple(_along(a.get(axis, 0.0), b.get(axis, 0.0), shares) for axis in AXES)


def _along(start: float, end: float, shares: list[float]) -> list[float]:
    travel = end - start
    return [start + share * travel for share in shares]
