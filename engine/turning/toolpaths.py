"""Tool paths of a turning job as passes of moves (design notes §8): pure functions of the
drawn geometry, no database.

Input is in (z, radius) mm as the DXF reader gives it; every Move states machine Z and
the DIAMETER as X. Arcs carry their radius and the centre relative to their start
(i radial as a radius, k axial); "ccw" is G3 (counter-clockwise with Z to the right and
the radius up), "cw" G2. Drawn tool paths are followed in the direction they were drawn:
the drawing holds the tool-centre path, its direction included.
"""
from __future__ import annotations

import math
from typing import Sequence

from importers.dxf_geometry import Arc, Line, Segment
from importers.dxf_profile import merged_bounds

from ..errors import EngineError
from .moves import Move, Pass
from .region import (CHORD_TOLERANCE_MM, Edge, distance_to_region, flattened_outline, free_intervals,
                     is_blocked)

__all__ = ["finish_passes", "drawn_rough_passes", "slot_passes", "thread_passes",
           "profile_rough_passes", "alternate", "distance_to_region"]

# A drawn line counts as axial (radial) when its ends differ by at most this in radius (Z).
STRAIGHT_TOLERANCE_MM = 0.001
# depth / depth-per-pass within this of a whole number is that number (1.2 / 0.4 → 3).
PASS_COUNT_NOISE = 1e-9
# Rough cuts shorter than this (mm) are left out: no pass for a sliver between two walls.
MIN_CUT_LENGTH_MM = 0.001
# More roughing levels than this means a depth per pass far too small for the blank.
MAX_ROUGH_LEVELS = 10_000
# Profile points nearer the axis than this (mm) do not count for its smallest radius.
ON_AXIS_MM = 0.001

# Where a user changes a number: the import-dxf flags (stored as the job parameters named
# after them, which SQL can change).
STOCK_FLAG, DEPTH_FLAG, ALLOWANCE_FLAG, CLEARANCE_FLAG = (
    "--stock-diameter (params.stock_diameter)", "--rough-depth (cutmotion depth_per_pass)",
    "--allowance (cutmotion allowance)", "params.clearance")


def rapid(z: float, radius: float) -> Move:
    return Move("rapid", z, 2.0 * radius)


def feed(z: float, radius: float) -> Move:
    return Move("feed", z, 2.0 * radius)


def cutting_move(segment: Segment) -> Move:
    """A line as a feed, an arc as G2/G3 with i/k from its start to its centre."""
    z, radius = segment.end
    if isinstance(segment, Line):
        return feed(z, radius)
    (start_z, start_r), (centre_z, centre_r) = segment.start, segment.centre
    return Move("ccw" if segment.ccw else "cw", z, 2.0 * radius, radius=segment.radius,
                i=centre_r - start_r, k=centre_z - start_z)


def require_clearance(clearance: float) -> None:
    if not clearance > 0:
        raise EngineError(f"clearance {clearance!r} mm must be above 0; set {CLEARANCE_FLAG} "
                          "to a positive distance")


def finish_passes(path: list[Segment], clearance: float) -> list[Pass]:
    """One pass along the path: approach lifted radially by clearance, the path's own
    segments, radial retract by clearance."""
    require_clearance(clearance)
    if not path:
        raise EngineError("the finish path is empty; draw the contour on the FINISH layer "
                          "or let the profile be finished")
    (start_z, start_r), (end_z, end_r) = path[0].start, path[-1].end
    moves = [rapid(start_z, start_r + clearance), feed(start_z, start_r)]
    moves += [cutting_move(segment) for segment in path]
    moves.append(rapid(end_z, end_r + clearance))
    return [moves]


def drawn_rough_passes(paths: list[list[Segment]], clearance: float) -> list[Pass]:
    """Seed-000 roughing: each drawn path one pass, outermost first. Per pass: rapid
    re-approach above the start (5), feed infeed (1), the drawn cut (2), rapid retract
    (3), rapid Z return (4); retract and return run clearance above the path's top."""
    require_clearance(clearance)
    ordered = sorted(paths, key=lambda path: -merged_bounds(path)[3])
    return [drawn_rough_pass(path, clearance) for path in ordered]


def drawn_rough_pass(path: list[Segment], clearance: float) -> Pass:
    (start_z, start_r), (end_z, _) = path[0].start, path[-1].end
    above = merged_bounds(path)[3] + clearance
    return [rapid(start_z, start_r + clearance), feed(start_z, start_r),
            *(cutting_move(segment) for segment in path),
            rapid(end_z, above), rapid(start_z, above)]


def radial_line(path: list[Segment], what: str) -> tuple[float, float, float]:
    """(z, outer radius, inner radius) of a path that is one radial line, else EngineError."""
    (z0, r0), (z1, r1) = path[0].start, path[-1].end
    straight = all(isinstance(s, Line) and abs(s.start[0] - z0) <= STRAIGHT_TOLERANCE_MM
                   and abs(s.end[0] - z0) <= STRAIGHT_TOLERANCE_MM for s in path)
    if not straight or abs(r0 - r1) <= STRAIGHT_TOLERANCE_MM:
        raise EngineError(f"{what} path from Z {z0:g} R {r0:g} to Z {z1:g} R {r1:g} is not a radial "
                          "line; draw each plunge as one line along drawing Y")
    return z0, max(r0, r1), min(r0, r1)


def slot_passes(paths: list[list[Segment]], clearance: float) -> list[Pass]:
    """Each drawn radial line one plunge, from the largest Z to the smallest: rapid above
    its outer end, feed to its inner end, rapid back out."""
    require_clearance(clearance)
    plunges = sorted((radial_line(path, "SLOT") for path in paths), key=lambda p: -p[0])
    return [[rapid(z, outer + clearance), feed(z, inner), rapid(z, outer + clearance)]
            for z, outer, inner in plunges]


def axial_line(path: list[Segment]) -> tuple[float, float, float] | None:
    """(start z, end z, radius) of a path that is one axial line, else None."""
    (z0, r0), (z1, r1) = path[0].start, path[-1].end
    straight = all(isinstance(s, Line) and abs(s.start[1] - r0) <= STRAIGHT_TOLERANCE_MM
                   and abs(s.end[1] - r0) <= STRAIGHT_TOLERANCE_MM for s in path)
    if not straight or abs(z1 - z0) <= STRAIGHT_TOLERANCE_MM:
        return None
    return z0, z1, (r0 + r1) / 2.0


def crest_and_root(paths: list[list[Segment]]) -> tuple[tuple[float, float, float], float]:
    """((start z, end z, radius) of the crest line, root radius) of a THREAD layer."""
    lines = [axial_line(path) for path in paths]
    if len(lines) != 2 or None in lines:
        raise EngineError(f"the THREAD layer holds {len(paths)} path(s), not two axial lines; draw "
                          "the crest line and the root line, each one line along drawing X")
    crest, root = sorted(lines, key=lambda line: -line[2])
    depth = crest[2] - root[2]
    if not depth > STRAIGHT_TOLERANCE_MM:
        raise EngineError(f"the THREAD crest and root lines lie at one radius ({crest[2]:g} mm), the "
                          "thread depth is 0; draw the root line below the crest line")
    return crest, root[2]


def require_thread_numbers(depth_per_pass: float, infeed_angle_deg: float, pitch: float) -> None:
    if not depth_per_pass > 0:
        raise EngineError(f"THREAD depth per pass @D {depth_per_pass!r} must be above 0; "
                          "change the @D code on the THREAD layer")
    if not 0 <= infeed_angle_deg < 90:
        raise EngineError(f"THREAD infeed angle @A {infeed_angle_deg!r}° must be from 0 up to "
                          "below 90; change the @A code on the THREAD layer")
    if not pitch > 0:
        raise EngineError(f"THREAD pitch @P {pitch!r} must be above 0; change the @P code on "
                          "the THREAD layer")


def pass_depths(depth: float, depth_per_pass: float) -> list[float]:
    """k·D for k = 1 … ceil(depth / D), the last one the full depth."""
    count = max(1, math.ceil(depth / depth_per_pass - PASS_COUNT_NOISE))
    return [min(k * depth_per_pass, depth) for k in range(1, count)] + [depth]


def thread_passes(paths: list[list[Segment]], depth_per_pass: float, infeed_angle_deg: float,
                  pitch: float, clearance: float) -> list[Pass]:
    """Threading passes to the depth between the drawn crest and root lines, along the
    drawn crest line's direction. Compound infeed: each pass starts depth·tan(@A) further
    back (towards the start side), so the tool cuts on one flank."""
    require_clearance(clearance)
    require_thread_numbers(depth_per_pass, infeed_angle_deg, pitch)
    (start_z, end_z, crest), root = crest_and_root(paths)
    back = 1.0 if start_z > end_z else -1.0   # +Z is "back" when the thread runs towards −Z
    slope, outside = math.tan(math.radians(infeed_angle_deg)), crest + clearance
    passes = []
    for depth in pass_depths(crest - root, depth_per_pass):
        z = start_z + back * depth * slope
        passes.append([rapid(z, outside), rapid(z, crest - depth),
                       Move("thread", end_z, 2.0 * (crest - depth), pitch=pitch),
                       rapid(end_z, outside), rapid(z, outside)])
    return passes


def alternate(first: list[Pass], second: list[Pass]) -> list[Pass]:
    """Crossed work steps: a1, b1, a2, b2, …, then the rest of the longer list."""
    crossed: list[Pass] = []
    for index in range(max(len(first), len(second))):
        crossed += [passes[index] for passes in (first, second) if index < len(passes)]
    return crossed


def smallest_radius(outline: Sequence[Segment]) -> float:
    """The smallest radius of the outline away from the axis."""
    radii = [r for segment in outline for r in (segment.start[1], segment.end[1]) if r > ON_AXIS_MM]
    radii += [r for segment in outline if isinstance(segment, Arc)
              for r in merged_bounds([segment])[2:] if r > ON_AXIS_MM]
    if not radii:
        raise EngineError("the profile lies on the axis, it has no radius to turn; draw the part "
                          "outline above the axis on layer 0")
    return min(radii)


def require_rough_numbers(outline: Sequence[Segment], stock_radius: float, depth_per_pass: float,
                          allowance: float, z_front: float, z_back: float) -> None:
    if not depth_per_pass > 0:
        raise EngineError(f"roughing depth per pass {depth_per_pass!r} mm must be above 0; give "
                          f"{DEPTH_FLAG} with a positive value")
    if not allowance >= 0:
        raise EngineError(f"finishing allowance {allowance!r} mm must be 0 or more; give "
                          f"{ALLOWANCE_FLAG} with a value ≥ 0")
    if not z_front > z_back:
        raise EngineError(f"the blank's front Z {z_front!r} must lie above its back Z {z_back!r}; "
                          "check the blank's length")
    if not outline:
        raise EngineError("the profile is empty; draw the part outline on layer 0")
    smallest = smallest_radius(outline)
    if not stock_radius > smallest:
        raise EngineError(f"blank radius {stock_radius!r} mm is not above the profile's smallest "
                          f"radius {smallest:g} mm, there is nothing to rough; give {STOCK_FLAG} "
                          f"above {2 * smallest:g}")
    if (stock_radius / depth_per_pass) > MAX_ROUGH_LEVELS:
        raise EngineError(f"roughing depth per pass {depth_per_pass:g} mm gives more than "
                          f"{MAX_ROUGH_LEVELS} levels on a {stock_radius:g} mm blank radius; "
                          f"give {DEPTH_FLAG} with a larger value")


def profile_rough_passes(outline: list[Segment], stock_radius: float, depth_per_pass: float,
                         allowance: float, z_front: float, z_back: float,
                         clearance: float) -> list[Pass]:
    """Rough from a blank (radius stock_radius over [z_back, z_front]) down to the part
    grown by the allowance: horizontal levels every depth_per_pass from the outside in;
    at each level every Z interval clear of the grown part (at that radius and above it,
    so the plunge is clear too) is one pass, cut from its larger Z towards −Z."""
    require_clearance(clearance)
    require_rough_numbers(outline, stock_radius, depth_per_pass, allowance, z_front, z_back)
    # Chords lie up to CHORD_TOLERANCE_MM inside convex arcs: keeping that much more
    # distance from the chords keeps the allowance from the true arcs.
    edges, keep = flattened_outline(outline), allowance + CHORD_TOLERANCE_MM
    passes, above = [], stock_radius
    for level in rough_levels(stock_radius, depth_per_pass):
        cuts = free_intervals(edges, level, keep, z_back, z_front, MIN_CUT_LENGTH_MM)
        if not cuts:
            break
        for low, high in reversed(cuts):
            start = entry_z(edges, level, keep, high, z_front, clearance)
            passes.append(rough_pass(start, low, level, above, stock_radius + clearance, clearance))
        above = level
    return passes


def rough_levels(stock_radius: float, depth_per_pass: float) -> list[float]:
    """stock − k·D for k = 1, 2, … while above the axis."""
    count = math.ceil(stock_radius / depth_per_pass - PASS_COUNT_NOISE)
    levels = [stock_radius - k * depth_per_pass for k in range(1, count + 1)]
    return [level for level in levels if level > ON_AXIS_MM]


def entry_z(edges: Sequence[Edge], level: float, keep: float, high: float, z_front: float,
            clearance: float) -> float:
    """A cut that reaches the blank's front face starts clearance in front of it, in the
    air, when nothing of the grown part is in the way there."""
    if high < z_front or is_blocked(edges, level, keep, z_front, z_front + clearance):
        return high
    return z_front + clearance


def rough_pass(start: float, end: float, level: float, above: float, safe: float,
               clearance: float) -> Pass:
    """Rapid at the safe radius (above the blank) to the start, rapid down to clearance
    above the level cut before, feed in, feed along the level, rapid out to the safe
    radius. Every Z of a pass was cut clear at every level above, so both verticals are
    free; travel between passes stays above the blank, so each pass stands alone (work
    steps can be crossed)."""
    moves = [rapid(start, safe)]
    if above + clearance < safe:
        moves.append(rapid(start, above + clearance))
    moves += [feed(start, level), feed(end, level), rapid(end, safe)]
    return moves
