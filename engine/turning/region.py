"""The part region of a turning profile in the (z, radius) plane, for roughing.

The region is the inside of a closed outline of lines and arcs (a half-profile plus its
closing segments, or a closed section). Arcs are flattened into chords that stay within
CHORD_TOLERANCE_MM of the arc, so every distance here is within that tolerance of the
exact one; callers that must keep a distance add the tolerance to it.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from functools import cached_property

import msgspec

from ..drawings.geometry import Arc, Point, Segment
from ..drawings.profile import sweep

CHORD_TOLERANCE_MM = 0.001   # 1 µm: largest gap between an arc and its chords
# Slopes and lengths below this (mm) count as zero in the interval algebra.
NUMERIC_ZERO = 1e-12

Edge = tuple[Point, Point]
Interval = tuple[float, float]


def flattened_outline(outline: Sequence[Segment]) -> list[Edge]:
    """The outline as straight edges; arcs as chords within CHORD_TOLERANCE_MM."""
    edges: list[Edge] = []
    for segment in outline:
        points = arc_points(segment) if isinstance(segment, Arc) else [segment.start, segment.end]
        edges.extend(zip(points, points[1:]))
    return edges


def arc_points(arc: Arc) -> list[Point]:
    """Start, chord corners, end of an arc, the chords within CHORD_TOLERANCE_MM."""
    radius, turn = arc.radius, sweep(arc)
    if radius <= CHORD_TOLERANCE_MM / 2.0:
        return [arc.start, arc.end]
    # A chord spanning angle φ leaves the sagitta radius·(1 − cos(φ/2)).
    max_step = 2.0 * math.acos(1.0 - CHORD_TOLERANCE_MM / radius)
    count = max(1, math.ceil(turn / max_step))
    (cz, cr), (sz, sr) = arc.centre, arc.start
    start_angle, sense = math.atan2(sr - cr, sz - cz), (1.0 if arc.ccw else -1.0)
    inner = [(cz + radius * math.cos(start_angle + sense * turn * n / count),
              cr + radius * math.sin(start_angle + sense * turn * n / count)) for n in range(1, count)]
    return [arc.start, *inner, arc.end]


def distance_to_edge(point: Point, edge: Edge) -> float:
    (pz, pr), ((z0, r0), (z1, r1)) = point, edge
    dz, dr = z1 - z0, r1 - r0
    length_sq = dz * dz + dr * dr
    t = 0.0 if length_sq < NUMERIC_ZERO else ((pz - z0) * dz + (pr - r0) * dr) / length_sq
    t = min(1.0, max(0.0, t))
    return math.hypot(pz - (z0 + t * dz), pr - (r0 + t * dr))


def is_inside(point: Point, edges: Iterable[Edge]) -> bool:
    """Even-odd rule: a ray towards +Z crosses the boundary an odd number of times."""
    pz, pr = point
    inside = False
    for (z0, r0), (z1, r1) in edges:
        if (r0 > pr) != (r1 > pr):
            crossing_z = z0 + (pr - r0) * (z1 - z0) / (r1 - r0)
            if crossing_z > pz:
                inside = not inside
    return inside


def distance_to_edges(point: Point, edges: Sequence[Edge]) -> float:
    """Distance from point to the region the edges enclose, 0 inside."""
    if is_inside(point, edges):
        return 0.0
    return min(distance_to_edge(point, edge) for edge in edges)


def distance_to_region(point: Point, outline: Sequence[Segment]) -> float:
    """Distance (mm) from a (z, radius) point to the part region, 0 inside; within
    CHORD_TOLERANCE_MM of the exact distance."""
    return distance_to_edges(point, flattened_outline(outline))


def linear_band(slope: float, offset: float, low: float, high: float) -> Interval | None:
    """{z : low < slope·z + offset < high} as (lo, hi), (−inf, inf) or None."""
    if abs(slope) < NUMERIC_ZERO:
        return (-math.inf, math.inf) if low < offset < high else None
    a, b = (low - offset) / slope, (high - offset) / slope
    return (min(a, b), max(a, b))


def capsule_on_level(edge: Edge, level: float, grow: float) -> Interval | None:
    """Z interval (open) where the line r = level is closer than grow to the edge."""
    pieces = [disk_on_level(end, level, grow) for end in edge]
    pieces.append(band_on_level(edge, level, grow))
    found = [piece for piece in pieces if piece is not None and piece[0] < piece[1]]
    if not found:
        return None
    return min(p[0] for p in found), max(p[1] for p in found)


def disk_on_level(centre: Point, level: float, grow: float) -> Interval | None:
    height = abs(level - centre[1])
    if height >= grow:
        return None
    half = math.sqrt(grow * grow - height * height)
    return centre[0] - half, centre[0] + half


def band_on_level(edge: Edge, level: float, grow: float) -> Interval | None:
    """Points of r = level whose foot on the edge's line lies on the edge, nearer than grow."""
    (z0, r0), (z1, r1) = edge
    dz, dr = z1 - z0, r1 - r0
    length = math.hypot(dz, dr)
    if length < NUMERIC_ZERO:
        return None
    # Foot parameter t = ((z − z0)·dz + (level − r0)·dr) / length², signed distance
    # s = ((z − z0)·dr − (level − r0)·dz) / length: both linear in z.
    along = linear_band(dz / length ** 2, (-z0 * dz + (level - r0) * dr) / length ** 2, 0.0, 1.0)
    across = linear_band(dr / length, (-z0 * dr - (level - r0) * dz) / length, -grow, grow)
    if along is None or across is None:
        return None
    lo, hi = max(along[0], across[0]), min(along[1], across[1])
    return (lo, hi) if lo < hi else None


def shadow_of_edge(edge: Edge, level: float, grow: float) -> Interval | None:
    """Open Z interval of the points of the edge grown by `grow` (a capsule) that lie at
    r ≥ level: a tool at r = level under or beside them would come too close. The capsule
    is convex, so its extreme Z above the level is its own extreme point if that lies
    above the level, else an end of its cut with the line r = level."""
    if max(edge[0][1], edge[1][1]) + grow <= level:
        return None
    on_level = capsule_on_level(edge, level, grow)
    left = min(edge, key=lambda p: (p[0], -p[1]))
    right = max(edge, key=lambda p: (p[0], p[1]))
    lo = left[0] - grow if left[1] >= level else (on_level[0] if on_level else None)
    hi = right[0] + grow if right[1] >= level else (on_level[1] if on_level else None)
    if lo is None or hi is None or lo >= hi:
        return None
    return lo, hi


def free_intervals(edges: Sequence[Edge], level: float, grow: float, z_low: float,
                   z_high: float, min_length: float) -> list[Interval]:
    """Closed Z intervals within [z_low, z_high] where a tool at r = level, and anywhere
    above it at the same Z, stays at least `grow` from the region; in increasing Z, each
    at least min_length long. The interior needs no test of its own: above
    any inside point lies a boundary point, whose capsule covers that Z."""
    blocked = sorted(filter(None, (shadow_of_edge(edge, level, grow) for edge in edges)))
    free, cursor = [], z_low
    for lo, hi in blocked:
        if lo > cursor:
            free.append((cursor, min(lo, z_high)))
        cursor = max(cursor, hi)
        if cursor >= z_high:
            break
    if cursor < z_high:
        free.append((cursor, z_high))
    return [(lo, hi) for lo, hi in free if hi - lo >= min_length]


def is_blocked(edges: Sequence[Edge], level: float, grow: float, z_low: float, z_high: float) -> bool:
    """Whether any Z of [z_low, z_high] at r = level (or above) is nearer than grow."""
    return free_intervals(edges, level, grow, z_low, z_high, 0.0) != [(z_low, z_high)]


def top_over(edges: Sequence[Edge], z_low: float, z_high: float) -> float:
    """The largest radius of the edges over the Z span [z_low, z_high] (0 when none reach it).
    Edges are straight, so the largest radius of each lies at an end of its clipped part."""
    top = 0.0
    for (z0, r0), (z1, r1) in edges:
        lo, hi = max(min(z0, z1), z_low), min(max(z0, z1), z_high)
        if lo > hi:
            continue
        if abs(z1 - z0) < NUMERIC_ZERO:
            top = max(top, r0, r1)
            continue
        top = max(top, *(r0 + (z - z0) * (r1 - r0) / (z1 - z0) for z in (lo, hi)))
    return top


class Surroundings(msgspec.Struct, frozen=True, dict=True):   # dict: room for the cached property
    """What a rapid move must stay clear of: the part (its flattened outline) and the blank
    (z_front, z_back, radius), kept at `clearance`."""
    edges: tuple[Edge, ...]
    blank: tuple[float, float, float] | None
    clearance: float

    def safe_radius(self, z_a: float, z_b: float) -> float:
        """A radius at which the tool may travel in Z between z_a and z_b: above the part and
        the blank over that span, by the clearance."""
        low, high = min(z_a, z_b), max(z_a, z_b)
        z_min, z_max, r_max = self.extent
        # Over the whole part (as a travel between passes is) the top is the largest radius.
        top = (r_max if low <= z_min and high >= z_max else top_over(self.edges, low, high)) + CHORD_TOLERANCE_MM
        if self.blank is not None and low <= self.blank[0] and high >= self.blank[1]:
            top = max(top, self.blank[2])
        return top + self.clearance

    @cached_property
    def extent(self) -> tuple[float, float, float]:
        """Smallest and largest Z and the largest radius of the part's edges."""
        points = [point for edge in self.edges for point in edge]
        return (min(z for z, _ in points), max(z for z, _ in points), max(max(r for _, r in points), 0.0))

    def z_span(self) -> tuple[float, float]:
        z_min, z_max, _ = self.extent
        zs = [z_min, z_max] + list(self.blank[:2] if self.blank else [])
        return min(zs), max(zs)
