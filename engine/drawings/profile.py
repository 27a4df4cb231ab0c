"""Chain segments into paths and find the turned profile on layer 0.

Machine coordinates for turning: drawing X is the machine Z axis, drawing Y the radius
(design notes §8). A profile drawn below the axis (all Y ≤ 0) is mirrored onto it, which
flips the sense of its arcs.

What "closed" means for a lathe profile: either a chain whose end meets its start, lying
on one side of the axis (a section of the part; one off the axis, with a bore, is read here
and refused when the job is made, engine/turning/reach.py), or a *half-profile*:
an open chain on one side of the axis whose two ends are its smallest and largest Z. Such
a chain is closed by the radial lines from its ends down to the axis and by the axis
between them (ends already on the axis make those lines zero long). Among all such
candidates on layer 0 the longest is the profile, and it must make up at least
PROFILE_SHARE_MIN of all geometry on layer 0: otherwise the drawing is something else (a
plate with holes, a full side view whose lines meet in T-junctions) or the outline is
broken by a gap, and taking the biggest piece would make a wrong part without a word.

Profiles are oriented the way a turning tool follows them: a half-profile starts at its
end with the larger Z and runs towards −Z; a closed profile runs counter-clockwise in the
(Z right, radius up) view, starting at its point of largest Z (then largest radius), so
its outer side is also followed towards −Z.
"""
from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from functools import cached_property
from typing import overload

import msgspec

from .geometry import Arc, Line, Point, Segment
from .read import DxfError

# End points closer than this (mm) are the same point when chaining.
END_MATCH_TOLERANCE_MM = 0.01
# The profile must be at least this share of the length of everything drawn on layer 0.
PROFILE_SHARE_MIN = 0.5
TWO_PI = 2.0 * math.pi
HALF_PI = math.pi / 2.0


@overload
def scaled(segment: Line, scale: float, mirror: bool = False) -> Line: ...
@overload
def scaled(segment: Arc, scale: float, mirror: bool = False) -> Arc: ...
def scaled(segment: Segment, scale: float, mirror: bool = False) -> Segment:
    """Drawing (x, y) → machine (z, radius) in mm; mirror maps radius −r to r."""
    if scale == 1.0 and not mirror:
        return segment  # segments are immutable: a millimetre drawing needs no copy
    sign = -1.0 if mirror else 1.0

    def point(p: Point) -> Point:
        return (p[0] * scale, sign * p[1] * scale)

    if isinstance(segment, Line):
        return Line(point(segment.start), point(segment.end), segment.handle)
    return Arc(point(segment.start), point(segment.end), point(segment.centre),
               segment.ccw != mirror, segment.handle)


def sweep(arc: Arc) -> float:
    """Angle (rad, 0 … 2π) the arc turns through from start to end in its own sense."""
    a0 = math.atan2(arc.start[1] - arc.centre[1], arc.start[0] - arc.centre[0])
    a1 = math.atan2(arc.end[1] - arc.centre[1], arc.end[0] - arc.centre[0])
    return ((a1 - a0) if arc.ccw else (a0 - a1)) % TWO_PI


def length(segment: Segment) -> float:
    if isinstance(segment, Line):
        return math.dist(segment.start, segment.end)
    return segment.radius * sweep(segment)


def bounds(segment: Segment) -> tuple[float, float, float, float]:
    """(z_min, z_max, r_min, r_max) including the extreme points of an arc."""
    (z0, r0), (z1, r1) = segment.start, segment.end
    z_min, z_max, r_min, r_max = min(z0, z1), max(z0, z1), min(r0, r1), max(r0, r1)
    if isinstance(segment, Line):
        return z_min, z_max, r_min, r_max
    (cz, cr), radius = segment.centre, segment.radius
    a0, a1 = math.atan2(r0 - cr, z0 - cz), math.atan2(r1 - cr, z1 - cz)
    if not segment.ccw:
        a0, a1 = a1, a0  # the same points, swept counter-clockwise from a1 to a0
    turn = (a1 - a0) % TWO_PI
    # The circle's extreme points at 0°, 90°, 180°, 270° count where the sweep reaches them.
    if -a0 % TWO_PI <= turn:
        z_max = cz + radius
    if (HALF_PI - a0) % TWO_PI <= turn:
        r_max = cr + radius
    if (math.pi - a0) % TWO_PI <= turn:
        z_min = cz - radius
    if (3 * HALF_PI - a0) % TWO_PI <= turn:
        r_min = cr - radius
    return z_min, z_max, r_min, r_max


def merged_bounds(segments: Sequence[Segment]) -> tuple[float, float, float, float]:
    z_mins, z_maxs, r_mins, r_maxs = zip(*map(bounds, segments))
    return min(z_mins), max(z_maxs), min(r_mins), max(r_maxs)


def signed_area(segments: Sequence[Segment]) -> float:
    """Shoelace area of a closed path of lines and arcs (> 0: counter-clockwise)."""
    area = 0.0
    for s in segments:
        area += (s.start[0] * s.end[1] - s.end[0] * s.start[1]) / 2.0
        if isinstance(s, Arc):
            theta = sweep(s)
            bulge_area = s.radius ** 2 / 2.0 * (theta - math.sin(theta))
            area += bulge_area if s.ccw else -bulge_area
    return area


class Chain(msgspec.Struct, dict=True):   # dict: room for the cached properties
    """Segments joined end to start, in order."""
    segments: list[Segment]
    closed: bool

    @property
    def start(self) -> Point:
        return self.segments[0].start

    @property
    def end(self) -> Point:
        return self.segments[-1].end

    @cached_property
    def length(self) -> float:
        return sum(map(length, self.segments))

    @cached_property
    def bounds(self) -> tuple[float, float, float, float]:
        return merged_bounds(self.segments)

    def reversed(self) -> Chain:
        return Chain([s.reversed() for s in reversed(self.segments)], self.closed)


class EndIndex:
    """End points of segments in grid cells of the match tolerance, for chaining in O(n)."""

    def __init__(self, segments: Sequence[Segment], tolerance: float):
        self.segments, self.tolerance = segments, tolerance
        self.used = [False] * len(segments)
        self.cells: dict[tuple[int, int], list[tuple[int, bool]]] = defaultdict(list)
        for index, segment in enumerate(segments):
            self.cells[self.cell(segment.start)].append((index, False))
            self.cells[self.cell(segment.end)].append((index, True))

    def cell(self, point: Point) -> tuple[int, int]:
        return (math.floor(point[0] / self.tolerance), math.floor(point[1] / self.tolerance))

    def take_at(self, point: Point, hint: int) -> tuple[int, bool] | None:
        """An unused segment with an end at point, marked used: (its index, whether the
        match is its end). Segment `hint` (the next one drawn) is tried first."""
        if hint < len(self.segments) and not self.used[hint] \
                and math.dist(self.segments[hint].start, point) <= self.tolerance:
            self.used[hint] = True
            return hint, False
        cx, cy = self.cell(point)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for index, at_end in self.cells.get((cx + dx, cy + dy), ()):
                    segment = self.segments[index]
                    if not self.used[index] and math.dist(
                            segment.end if at_end else segment.start, point) <= self.tolerance:
                        self.used[index] = True
                        return index, at_end
        return None


def chain_segments(segments: Sequence[Segment], tolerance: float = END_MATCH_TOLERANCE_MM) -> list[Chain]:
    """Join segments whose ends meet within tolerance into chains, in drawing order of
    their first segment; where more than two ends meet, the next drawn segment continues
    if it can, else the first drawn one."""
    index = EndIndex(segments, tolerance)
    chains = []
    for number in range(len(segments)):
        if index.used[number]:
            continue
        index.used[number] = True
        chains.append(grown_chain(number, index, tolerance))
    return chains


def grown_chain(first: int, index: EndIndex, tolerance: float) -> Chain:
    segments = index.segments
    forward, last, origin = [segments[first]], first, segments[first].start
    while len(forward) == 1 or math.dist(forward[-1].end, origin) > tolerance:
        found = index.take_at(forward[-1].end, last + 1)
        if found is None:
            break
        last, at_end = found
        forward.append(segments[last].reversed() if at_end else segments[last])
    if len(forward) > 1 and math.dist(forward[-1].end, origin) <= tolerance:
        return Chain(forward, True)
    backward: list[Segment] = []
    while (found := index.take_at((backward[-1] if backward else forward[0]).start, len(segments))) is not None:
        number, at_end = found
        backward.append(segments[number] if at_end else segments[number].reversed())
    return Chain(backward[::-1] + forward, False)


class Profile(msgspec.Struct):
    """The part outline in machine coordinates (z, radius) in mm, oriented for turning.

    closed_by_axis: the segments are an open half-profile; the radial lines from its ends
    to the axis and the axis between them close it (see `closing_segments`).
    mirrored: it was drawn below the axis and has been mirrored onto it.
    bounds: (z_min, z_max, r_min, r_max) of the drawn segments."""
    segments: list[Segment]
    closed_by_axis: bool
    bounds: tuple[float, float, float, float]
    mirrored: bool = False

    @property
    def start(self) -> Point:
        return self.segments[0].start

    @property
    def end(self) -> Point:
        return self.segments[-1].end

    def closing_segments(self) -> list[Line]:
        """End → axis → start for a half-profile (zero-length lines left out); [] if closed."""
        if not self.closed_by_axis:
            return []
        corners = [self.end, (self.end[0], 0.0), (self.start[0], 0.0), self.start]
        return [Line(a, b) for a, b in zip(corners, corners[1:]) if math.dist(a, b) > END_MATCH_TOLERANCE_MM]


class Candidate(msgspec.Struct):
    chain: Chain  # as drawn; mirrored onto the axis only once chosen
    mirrored: bool
    closed_by_axis: bool


def side_of_axis(chain: Chain, tolerance: float) -> str:
    """'above', 'below' or 'across' (touching the axis counts as either side)."""
    _, _, r_min, r_max = chain.bounds
    if r_min >= -tolerance:
        return "above"
    return "below" if r_max <= tolerance else "across"


def as_candidate(chain: Chain, tolerance: float) -> Candidate | str:
    """The chain as a profile candidate, or the reason it cannot be one."""
    side = side_of_axis(chain, tolerance)
    if side == "across":
        return "it crosses the axis (drawing Y = 0); draw only the half above the axis"
    if chain.closed:
        return Candidate(chain, side == "below", False)
    z_min, z_max, _, _ = chain.bounds
    end_zs = sorted((chain.start[0], chain.end[0]))
    if z_max - z_min <= tolerance:
        return "it is open and has no extent along Z, so the axis cannot close it"
    if end_zs[0] - z_min > tolerance or z_max - end_zs[1] > tolerance:
        return (f"it is open and its ends (Z {chain.start[0]:g} and {chain.end[0]:g}) are not its "
                f"smallest and largest Z ({z_min:g} … {z_max:g}), so the axis cannot close it")
    return Candidate(chain, side == "below", True)


def oriented(candidate: Candidate) -> list[Segment]:
    """The candidate's segments mirrored if need be and in turning order (module doc)."""
    chain = candidate.chain
    if candidate.mirrored:
        chain = Chain([scaled(s, 1.0, mirror=True) for s in chain.segments], chain.closed)
    if candidate.closed_by_axis:
        return (chain if chain.start[0] >= chain.end[0] else chain.reversed()).segments
    segments = chain.segments if signed_area(chain.segments) > 0 else chain.reversed().segments
    first = max(range(len(segments)), key=lambda i: (round(segments[i].start[0], 6), segments[i].start[1]))
    return segments[first:] + segments[:first]


def find_profile(chains: Sequence[Chain], tolerance: float = END_MATCH_TOLERANCE_MM, layer: str = "0") -> Profile:
    """The profile among the chains of the profile layer (machine coordinates, mm), or DxfError."""
    if not chains:
        raise DxfError(f"layer {layer} has no profile: no LINE, ARC, CIRCLE, polyline, SPLINE or ELLIPSE "
                       f"in model space on layer {layer}; draw the part outline on layer {layer}")
    verdicts = [as_candidate(chain, tolerance) for chain in chains]
    candidates = [v for v in verdicts if isinstance(v, Candidate)]
    if not candidates:
        longest = max(range(len(chains)), key=lambda i: chains[i].length)
        reason = verdicts[longest]
        assert isinstance(reason, str)   # no chain is a candidate: each verdict is why not
        raise DxfError(no_profile_message(chains, longest, reason, layer))
    best = max(candidates, key=lambda c: c.chain.length)
    total = sum(chain.length for chain in chains)
    if best.chain.length < PROFILE_SHARE_MIN * total:
        raise DxfError(minor_profile_message(best, total, len(chains), layer))
    z_min, z_max, r_min, r_max = best.chain.bounds
    box = (z_min, z_max, -r_max, -r_min) if best.mirrored else best.chain.bounds
    return Profile(oriented(best), best.closed_by_axis, box, best.mirrored)


def handles_of(chain: Chain, limit: int = 5) -> str:
    handles = list(dict.fromkeys(s.handle for s in chain.segments if s.handle))
    return ", ".join(handles[:limit]) + (", …" if len(handles) > limit else "")


def no_profile_message(chains: Sequence[Chain], longest: int, reason: str, layer: str = "0") -> str:
    chain = chains[longest]
    return (f"layer {layer} has no closed profile: none of its {len(chains)} chain(s) is closed or a "
            f"half-profile the axis can close; the longest ({chain.length:.3f} mm, handles "
            f"{handles_of(chain)}) fails because {reason}")


def minor_profile_message(best: Candidate, total: float, count: int, layer: str = "0") -> str:
    return (f"layer {layer} has no clear profile: the longest closed chain or half-profile (handles "
            f"{handles_of(best.chain)}, {best.chain.length:.3f} mm) is only "
            f"{100 * best.chain.length / total:.0f}% of the {total:.3f} mm drawn on layer {layer} in "
            f"{count} chains; join the outline into one chain (ends within {END_MATCH_TOLERANCE_MM} mm, "
            f"no T-junctions) and move other lines to another layer")
