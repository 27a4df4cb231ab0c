"""The shapes of a hobbing picture, in the DIN frame the simulation works in (reference §A7: X from
the work axis toward the hob, Z up along it, the gear's top face at Z = 0): a unit's section, the
hob's outline seen along X or along Y, where a cut reaches full depth and which way its pass
feeds. Pure functions of the simulation's recording (engine.simulation.hobbing.recorded)."""
from __future__ import annotations

import math

import msgspec
import numpy as np

OUTLINE_STEPS = 96      # points around a hob outline


class Pass(msgspec.Struct, frozen=True):
    axis: str           # "Z" axial pass, "X" radial plunge, "Y" tangential feed
    start: dict         # DIN pose where the pass begins
    end: dict           # and where it ends


def unit_section(unit) -> list[tuple[float, float]]:
    """(X, Z) corners of a unit's axial section through the work axis: its tip radius over its
    face width on both sides of the axis (a taper's cone slants)."""
    top, bottom = unit.radius_at(unit.z_high), unit.radius_at(unit.z_low)
    return [(-top, unit.z_high), (top, unit.z_high), (bottom, unit.z_low), (-bottom, unit.z_low)]


def hob_side_outline(x: float, z: float, radius: float, half_length: float, swivel: float) -> tuple:
    """The hob's tip cylinder seen along Y (its axis in the Y–Z plane swivelled by A about X): the
    upper half of an ellipse of half-axes r (X) and r·cos A (Z) raised by (L/2)·|sin A|, the
    lower half lowered by as much, joined by straight sides at X = ±r."""
    a = math.radians(swivel)
    rise = half_length * abs(math.sin(a))
    upper = np.linspace(0.0, math.pi, OUTLINE_STEPS // 2 + 1)
    lower = upper + math.pi
    theta = np.concatenate([upper, lower, upper[:1]])
    lift = np.concatenate([np.full(len(upper), rise), np.full(len(lower), -rise), [rise]])
    return x + radius * np.cos(theta), z + radius * math.cos(a) * np.sin(theta) + lift


def hob_extent(radius: float, half_length: float, swivel: float) -> float:
    """How far above and below its centre the swivelled hob reaches (engine.simulation.hobbing.envelope)."""
    a = math.radians(swivel)
    return radius * abs(math.cos(a)) + half_length * abs(math.sin(a))


def hob_front_corners(y: float, z: float, radius: float, half_length: float, swivel: float) -> list:
    """The hob seen along X (from the hob's side: Y to the right, Z up): a rectangle of its length
    along the swivelled axis and its tip diameter across it, centred where Y puts it."""
    along, across = axis_direction(swivel), (-math.sin(math.radians(swivel)), math.cos(math.radians(swivel)))
    centre = hob_centre(y, z, swivel)
    return [(centre[0] + s * half_length * along[0] + t * radius * across[0],
             centre[1] + s * half_length * along[1] + t * radius * across[1]) for s, t in
            ((-1, -1), (1, -1), (1, 1), (-1, 1))]


def axis_direction(swivel: float) -> tuple[float, float]:
    a = math.radians(swivel)
    return math.cos(a), math.sin(a)


def hob_centre(y: float, z: float, swivel: float) -> tuple[float, float]:
    """Y moves the hob along its own axis (engine.simulation.hobbing.envelope.centres)."""
    along = axis_direction(swivel)
    return y * along[0], z + y * along[1]


def along_hob(u: float, y: float, z: float, swivel: float) -> tuple[float, float]:
    """The point u mm along the hob axis from its centre, seen along X."""
    centre, along = hob_centre(y, z, swivel), axis_direction(swivel)
    return centre[0] + u * along[0], centre[1] + u * along[1]


def cut_pass(cut) -> Pass | None:
    """The feed of a cut after its infeed: the moves along Z (with X for taper and crowning),
    else along Y (tangential worm wheel), else the radial plunge."""
    for axis in ("Z", "Y", "X"):
        moving = [move for move in cut.moves if _moves_along(move, axis)]
        if moving:
            return Pass(axis, moving[0].start, moving[-1].end)
    return None


def axial_profile(cut) -> tuple[list[float], list[float]]:
    """X and Z of the hob centre along the cut's moves in Z (the pass, crowned or tapered)."""
    along = [move for move in cut.moves if _moves_along(move, "Z")]
    poses = [along[0].start, *(move.end for move in along)] if along else []
    return [pose["X"] for pose in poses], [pose["Z"] for pose in poses]


def _moves_along(move, axis: str) -> bool:
    return axis in move.start and abs(move.end[axis] - move.start[axis]) > 1e-9


def full_depth_pose(cut, unit) -> dict | None:
    """Where the cut stands at the unit's mid-face (its nominal full depth, §B3; a crowned gear's
    largest centre distance, §B11), else at the wheel's centre plane Y = 0 (tangential), else at
    its deepest (a plunge)."""
    middle = (unit.z_low + unit.z_high) / 2
    for axis, value in (("Z", middle), ("Y", 0.0)):
        pose = _crossing(cut.moves, axis, value)
        if pose is not None and {"X", "Z"} <= pose.keys():
            return pose
    return min(cut.poses, key=lambda pose: pose["X"], default=None)


def _crossing(moves, axis: str, value: float) -> dict | None:
    for move in moves:
        if not _moves_along(move, axis):
            continue
        low, high = sorted((move.start[axis], move.end[axis]))
        if low <= value <= high:
            share = (value - move.start[axis]) / (move.end[axis] - move.start[axis])
            return {key: move.start.get(key, end) + share * (end - move.start.get(key, end))
                    for key, end in move.end.items()}
    return None


def approach_pose(cuts) -> dict | None:
    """Where the hob stands before the first cut's first feed move: the approach (§B7)."""
    return dict(cuts[0].poses[0]) if cuts and cuts[0].poses else None
