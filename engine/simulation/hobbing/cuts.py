"""A cut as the simulation follows it: consecutive G1 moves of the intended cut (coupled,
spindle turning) between a rapid or an uncoupling. What it reports per cut (reference §B3,
§B5, §B7, §B8): the centre distance and depth reached, the stock it leaves above the intended
root, the run-out (how far the pass carries the hob centre beyond the face it leaves; for a
tangential worm-wheel pass, the hob's trailing end beyond the wheel's centre plane), and the
feeds per workpiece revolution (radial infeed and pass, and along an axial pass's path: the
spacing of its feed marks)."""
from __future__ import annotations

import math

import msgspec

from .report import CutSummary
from .solids import Solid


class Cut(msgspec.Struct):
    """One cut followed: from a coupling's start to its end, with its moves and each unit's reach before it."""
    number: int
    line: str
    teeth: int
    table_speed: float                  # workpiece revolutions per minute (S·|k_B|)
    reach_before: dict = {}   # id(unit) -> its reach when the cut began
    moves: list = []   # (start DIN, end DIN, velocities {axis: mm/min})

    def add(self, start: dict, end: dict, velocities: dict) -> None:
        self.moves.append((start, end, velocities))

    def pass_moves(self, axis: str) -> list:
        return [move for move in self.moves
                if axis in move[1] and abs(move[1][axis] - move[0].get(axis, move[1][axis])) > 1e-9]


def run_out(cut: Cut, unit: Solid, half_length: float) -> float | None:
    """mm beyond the face (or centre plane) the pass leaves; None for a plunge without a pass."""
    axial = cut.pass_moves("Z")
    if axial:
        start, end = axial[0][0]["Z"], axial[-1][1]["Z"]
        return unit.z_low - end if end < start else end - unit.z_high
    tangential = cut.pass_moves("Y")
    if tangential:
        start, end = tangential[0][0]["Y"], tangential[-1][1]["Y"]
        return -(end + half_length) if end < start else end - half_length
    return None


def feed_per_revolution(cut: Cut, axes: tuple) -> float | None:
    """The largest feed along `axes` of the cut's moves, per workpiece revolution."""
    speeds = [abs(move[2].get(axis, 0.0)) for move in cut.moves for axis in axes]
    speeds = [speed for speed in speeds if speed > 0]
    if not speeds or cut.table_speed <= 0:
        return None
    return max(speeds) / cut.table_speed


def mark_feed(cut: Cut) -> float | None:
    """The largest path feed of the cut's axial pass moves (Z moving), per workpiece revolution:
    the spacing of the feed marks (§B6). A taper's or a crowning's G1 X Z moves the hob along
    the slant, so X counts with Z; None for a cut without an axial pass (a worm wheel's)."""
    speeds = [math.hypot(velocities.get("X", 0.0), velocities["Z"]) for _, _, velocities in cut.moves
              if velocities.get("Z")]
    if not speeds or cut.table_speed <= 0:
        return None
    return max(speeds) / cut.table_speed


def radial_feed(cut: Cut) -> float | None:
    radial = [move for move in cut.moves if set(move[2]) == {"X"}]
    return feed_per_revolution(Cut(cut.number, cut.line, cut.teeth, cut.table_speed, moves=radial), ("X",))


def summary(cut: Cut, unit: Solid, half_length: float) -> CutSummary:
    centre = min(end["X"] for _, end, _ in cut.moves)
    depths = [radius - reach for radius, reach in zip(unit.radius, unit.reach) if reach != math.inf]
    depth = max(depths) if depths else 0.0
    stock = max(unit.stock()) if len(depths) == len(unit.reach) else math.inf
    pass_axes = ("Z",) if cut.pass_moves("Z") else ("Y",)
    return CutSummary(cut.number, unit.name, centre, depth, stock, run_out(cut, unit, half_length),
                      radial_feed(cut), feed_per_revolution(cut, pass_axes), mark_feed(cut))
