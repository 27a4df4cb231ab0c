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
from collections.abc import Sequence

from ..drawings.geometry import Arc, Line, Segment
from ..drawings.profile import merged_bounds
from ..errors import EngineError
from .moves import Move, Pass
from .region import (
    CHORD_TOLERANCE_MM,
    Edge,
    Surroundings,
    distance_to_region,
    flattened_outline,
    free_intervals,
    is_blocked,
    top_over,
)

__all__ = ["finish_passes", "drawn_rough_passes", "slot_passes", "thread_passes",
           "profile_rough_passes", "alternate", "up_then_across", "standalone", "distance_to_region"]

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
# A rough level along a flat lies this much (mm) beyond the allowance, clear of rounding.
LEVEL_NOISE_MM = 1e-6

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


def start_direction(segment: Segment) -> tuple[float, float]:
    """Unit tangent (z, r) of a segment at its start, in its direction of travel."""
    (z0, r0) = segment.start
    if isinstance(segment, Line):
        dz, dr = segment.end[0] - z0, segment.end[1] - r0
    else:
        cz, cr = segment.centre
        sense = 1.0 if segment.ccw else -1.0
        dz, dr = -sense * (r0 - cr), sense * (z0 - cz)
    length = math.hypot(dz, dr) or 1.0
    return dz / length, dr / length


def finish_passes(path: list[Segment], clearance: float) -> list[Pass]:
    """One pass along the path: rapid to clearance before its start — back along its first
    direction and out along its outward normal (the part lies left of a path drawn from the
    front backwards), so in the air in front of the material, never below the axis — feed in, the path's own
    segments; the travel radius in and out is added by standalone()."""
    require_clearance(clearance)
    if not path:
        raise EngineError("the finish path is empty; draw the contour on the FINISH layer "
                          "or let the profile be finished")
    (start_z, start_r), (dz, dr) = path[0].start, start_direction(path[0])
    outward_z, outward_r = dr, -dz
    # A path starting on the axis (a dome, a ball end, a cone point) would put that point
    # below the axis, through the part's other side: it comes in along the axis instead,
    # from in front of the point (radius 0, diameter X0), where no material is.
    approach_r = max(0.0, start_r + clearance * (outward_r - dr))
    moves = [rapid(start_z + clearance * (outward_z - dz), approach_r), feed(start_z, start_r)]
    return [moves + [cutting_move(segment) for segment in path]]


def drawn_rough_passes(paths: list[list[Segment]], clearance: float) -> list[Pass]:
    """Seed-000 roughing: each drawn path one pass, outermost first: rapid down to clearance
    above its start, feed in, the drawn cut; retract and return run at the travel radius
    (standalone())."""
    require_clearance(clearance)
    ordered = sorted(paths, key=lambda path: -merged_bounds(path)[3])
    return [drawn_rough_pass(path, clearance) for path in ordered]


def drawn_rough_pass(path: list[Segment], clearance: float) -> Pass:
    start_z, start_r = path[0].start
    moves = [rapid(start_z, start_r + clearance), feed(start_z, start_r),
             *(cutting_move(segment) for segment in path)]
    return moves + _off_a_face(path[-1], clearance)


def _off_a_face(last: Segment, clearance: float) -> list[Move]:
    """A cut that ends moving radially (facing) has just made a face: the tool leaves it
    along +Z, towards the part's free end, before the X retract would drag across it."""
    (z0, r0), (z1, r1) = last.start, last.end
    if isinstance(last, Line) and abs(z1 - z0) <= STRAIGHT_TOLERANCE_MM < abs(r1 - r0):
        return [rapid(z1 + clearance, r1)]
    return []


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
    """Each drawn radial line one plunge, from the largest Z to the smallest: rapid down to
    clearance above its outer end, feed to its inner end, rapid back out."""
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
    found = [axial_line(path) for path in paths]
    lines = [line for line in found if line is not None]
    if len(found) != 2 or len(lines) != 2:
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


def thread_run_in(around: Surroundings | None, start_z: float, back: float, crest: float, root: float,
                  pitch: float, clearance: float) -> float:
    """How far before the drawn start (towards the start side) every pass begins, so its
    in-feed happens in the air: clearance when nothing at the root radius or above lies
    there, else beyond the part's free end (+Z) by clearance, through material no larger
    than the crest. A whole number of pitches, so the run-in leaves the helix where the
    drawing has it. Material before a start on the chuck side (−Z), or larger than the
    crest, would be cut by the run-in: refused."""
    needed = clearance
    if around is not None:
        low, high = around.z_span()
        outer_end = high if back > 0 else low
        beyond = start_z + back * STRAIGHT_TOLERANCE_MM
        top = top_over(around.edges, *sorted((beyond, outer_end)))
        if top >= root:
            if back < 0 or top > crest + STRAIGHT_TOLERANCE_MM:
                raise EngineError(
                    f"THREAD starting at Z {start_z:g}: the part continues before it (radius {top:g} mm, "
                    f"root {root:g} mm) up to Z {outer_end:g}, so the passes' run-in would cut it; draw the "
                    "thread from the part's free end, or draw a thread relief groove before its start")
            needed = max(needed, back * (outer_end - start_z) + clearance)
    return math.ceil(needed / pitch - PASS_COUNT_NOISE) * pitch


def thread_passes(paths: list[list[Segment]], depth_per_pass: float, infeed_angle_deg: float,
                  pitch: float, clearance: float, around: Surroundings | None = None) -> list[Pass]:
    """Threading passes to the depth between the drawn crest and root lines, along the
    drawn crest line's direction, each begun a run-in before the drawn start. Compound
    infeed: the tool cuts on the flank it advances along, so a pass at depth d starts
    (H − d)·tan(@A) further towards the start side than the last one (depth H), which
    lies on the drawn thread."""
    require_clearance(clearance)
    require_thread_numbers(depth_per_pass, infeed_angle_deg, pitch)
    (start_z, end_z, crest), root = crest_and_root(paths)
    back = 1.0 if start_z > end_z else -1.0   # +Z is "back" when the thread runs towards −Z
    slope, full = math.tan(math.radians(infeed_angle_deg)), crest - root
    first_z = start_z + back * thread_run_in(around, start_z, back, crest, root, pitch, clearance)
    passes = []
    for depth in pass_depths(full, depth_per_pass):
        z = first_z + back * (full - depth) * slope
        passes.append([rapid(z, crest + clearance), rapid(z, crest - depth),
                       Move("thread", end_z, 2.0 * (crest - depth), pitch=pitch)])
    return passes


def standalone(passes: list[Pass], around: Surroundings) -> list[Pass]:
    """Each pass entered at one travel radius — above the part, the blank and the passes
    themselves over the whole job — by Z there first and then X down, and left by X up to
    it: any pass may then follow any other (crossed work steps, tool changes)."""
    if not passes:
        return passes
    low, high = around.z_span()
    zs = [move.z for one in passes for move in one] + [low, high]
    travel = max(around.safe_radius(min(zs), max(zs)),
                 max(move.x / 2.0 for one in passes for move in one) + around.clearance)
    return [without_standstills([rapid(one[0].z, travel), *one, rapid(one[-1].z, travel)]) for one in passes]


def without_standstills(moves: Pass) -> Pass:
    """The moves without rapids to where the tool already is."""
    kept = moves[:1]
    for move in moves[1:]:
        if not (move.kind == "rapid" and (move.z, move.x) == (kept[-1].z, kept[-1].x)):
            kept.append(move)
    return kept


def alternate(first: list[Pass], second: list[Pass]) -> list[Pass]:
    """Crossed work steps: a1, b1, a2, b2, …, then the rest of the longer list."""
    crossed: list[Pass] = []
    for index in range(max(len(first), len(second))):
        crossed += [passes[index] for passes in (first, second) if index < len(passes)]
    return crossed


def up_then_across(passes: list[Pass]) -> list[Pass]:
    """Passes run one after the other without a tool change between them (alternated work steps):
    each is entered from the end of the one before by X up to the higher of both radii first, then
    Z, then X down, never diagonally across the corner of material neither pass has cut."""
    linked = passes[:1]
    for one in passes[1:]:
        end, start = linked[-1][-1], one[0]
        top = max(end.x, start.x) / 2.0
        here = Move("rapid", end.z, end.x)
        linked.append(without_standstills([here, rapid(end.z, top), rapid(start.z, top), *one])[1:])
    return linked


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
    largest = max(r for edge in flattened_outline(outline) for _, r in edge)
    if stock_radius < largest - CHORD_TOLERANCE_MM:
        raise EngineError(f"blank radius {stock_radius:g} mm is below the part's largest radius {largest:g} mm: "
                          f"the part does not fit in the blank; give {STOCK_FLAG} of at least {2 * largest:g}")
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
    for level in rough_levels(stock_radius, depth_per_pass, grown_flats(edges, keep)):
        cuts = free_intervals(edges, level, keep, z_back, z_front, MIN_CUT_LENGTH_MM)
        if not cuts:
            break
        for low, high in reversed(cuts):
            start = entry_z(edges, level, keep, high, z_front, clearance)
            passes.append(rough_pass(start, low, level, above, stock_radius + clearance, clearance))
        above = level
    return passes


def rough_levels(stock_radius: float, depth_per_pass: float, floors: list[float]) -> list[float]:
    """stock − k·D for k = 1, 2, … while above the axis, and every floor below the blank
    (the flats of the part grown by the allowance, so each is roughed exactly to it),
    from the outside in. A depth beyond the whole blank still leaves the floors."""
    count = math.ceil(stock_radius / depth_per_pass - PASS_COUNT_NOISE)
    levels = [stock_radius - k * depth_per_pass for k in range(1, count + 1)]
    levels += [floor for floor in floors if floor < stock_radius]
    return sorted({level for level in levels if level > ON_AXIS_MM}, reverse=True)


def grown_flats(edges: Sequence[Edge], keep: float) -> list[float]:
    """The radius of every axial edge of the outline above the axis, grown by `keep` (and a
    hair more, so that level is judged free of the flat it runs along)."""
    return [r0 + keep + LEVEL_NOISE_MM for (z0, r0), (z1, r1) in edges
            if abs(r0 - r1) <= STRAIGHT_TOLERANCE_MM and abs(z0 - z1) > STRAIGHT_TOLERANCE_MM and r0 > ON_AXIS_MM]


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
