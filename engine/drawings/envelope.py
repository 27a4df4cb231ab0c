"""The outline of a turned part seen from the side: the upper envelope of what is drawn above
its axis (issue 17).

A turned surface seen from the side shows, at each Z, its largest radius as the outline;
everything drawn below that (edges where a shoulder meets a diameter, thread roots, a slot,
a section's inner lines) is inside the part. So the half-profile of a side view is, Z by Z,
the highest drawn line above the axis, with radial steps where the highest line jumps.
Coordinates are machine (z, radius) in mm, the axis at radius 0; the lines and arcs of the
envelope are pieces of the drawn ones, so a finish pass along it is on the drawing.
"""
from __future__ import annotations

import math

import msgspec

from .geometry import Arc, Line, Segment
from .profile import END_MATCH_TOLERANCE_MM, sweep
from .read import DxfError

SAME_Z = 1e-7          # breakpoints closer than this (mm) are one
ON_PIECE = 1e-4        # two pieces this close (mm) at a bisected Z meet there


class Piece(msgspec.Struct, frozen=True):
    """A part of a drawn line or arc over which the radius is a function of Z: z0 < z1.
    centre/radius/upper describe an arc piece (upper: on the upper half of its circle)."""
    z0: float
    z1: float
    start_r: float
    end_r: float
    centre: tuple[float, float] | None = None
    radius: float = 0.0
    upper: bool = True

    def r_at(self, z: float) -> float:
        if self.centre is None:
            return self.start_r + (self.end_r - self.start_r) * (z - self.z0) / (self.z1 - self.z0)
        dz = min(self.radius, abs(z - self.centre[0]))
        rise = math.sqrt(self.radius * self.radius - dz * dz)
        return self.centre[1] + (rise if self.upper else -rise)

    def covers(self, z: float) -> bool:
        return self.z0 - SAME_Z <= z <= self.z1 + SAME_Z

    def segment(self, z_a: float, z_b: float) -> Segment:
        """The piece from z_a to z_b (either order), as a drawn segment."""
        start, end = (z_a, self.r_at(z_a)), (z_b, self.r_at(z_b))
        if self.centre is None:
            return Line(start, end)
        # Along the upper half of a circle towards +Z is clockwise, along the lower counter-clockwise.
        return Arc(start, end, self.centre, (z_b > z_a) != self.upper)


def pieces_of(segment: Segment) -> list[Piece]:
    """The segment's pieces above the axis (radius ≥ 0) that are functions of Z."""
    if isinstance(segment, Line):
        return line_pieces(segment)
    return [piece for part in arc_parts(segment) for piece in line_or_arc_piece(part)]


def line_pieces(line: Line) -> list[Piece]:
    (z0, r0), (z1, r1) = sorted((line.start, line.end))
    if z1 - z0 <= SAME_Z or max(r0, r1) <= 0.0:
        return []
    if min(r0, r1) < 0.0:   # crosses the axis: the part above it
        z_axis = z0 + (z1 - z0) * (0.0 - r0) / (r1 - r0)
        (z0, r0), (z1, r1) = ((z_axis, 0.0), (z1, r1)) if r1 > 0 else ((z0, r0), (z_axis, 0.0))
    return [Piece(z0, z1, r0, r1)] if z1 - z0 > SAME_Z else []


def arc_parts(arc: Arc) -> list[tuple[float, float, Arc]]:
    """(start angle, end angle, arc) counter-clockwise sub-arcs split where Z is extreme
    (angles 0 and π) and where the arc crosses the axis."""
    ccw = arc if arc.ccw else arc.reversed()
    (cz, cr), radius = ccw.centre, ccw.radius
    begin = math.atan2(ccw.start[1] - cr, ccw.start[0] - cz)
    turn = sweep(ccw)
    cuts = [0.0, math.pi]
    if radius > abs(cr):
        crossing = math.asin(-cr / radius)
        cuts += [crossing, math.pi - crossing]
    inner = sorted((cut - begin) % (2 * math.pi) for cut in cuts)
    offsets = [0.0] + [offset for offset in inner if 1e-12 < offset < turn - 1e-12] + [turn]
    return [(begin + a, begin + b, ccw) for a, b in zip(offsets, offsets[1:])]


def line_or_arc_piece(part: tuple[float, float, Arc]) -> list[Piece]:
    a, b, arc = part
    (cz, cr), radius = arc.centre, arc.radius
    middle = (a + b) / 2.0
    if cr + radius * math.sin(middle) < 0.0:
        return []
    z_a, z_b = cz + radius * math.cos(a), cz + radius * math.cos(b)
    if abs(z_b - z_a) <= SAME_Z:
        return []
    r_a, r_b = cr + radius * math.sin(a), cr + radius * math.sin(b)
    (z0, r0), (z1, r1) = sorted(((z_a, r_a), (z_b, r_b)))
    return [Piece(z0, z1, r0, r1, arc.centre, radius, math.sin(middle) > 0.0)]


def crossings(first: Piece, second: Piece) -> list[float]:
    """Z of the points where two pieces meet inside both Z ranges."""
    low, high = max(first.z0, second.z0), min(first.z1, second.z1)
    if high - low <= SAME_Z:
        return []
    return [z for z in candidate_zs(first, second, low, high)
            if low < z < high and abs(first.r_at(z) - second.r_at(z)) <= ON_PIECE]


def candidate_zs(first: Piece, second: Piece, low: float, high: float) -> list[float]:
    """Where the difference of the two radii changes sign, found by bisection on a fine grid:
    lines and circle arcs cross at most twice, 64 cells separate such crossings."""
    found, cells = [], 64
    zs = [low + (high - low) * k / cells for k in range(cells + 1)]
    differences = [first.r_at(z) - second.r_at(z) for z in zs]
    for (z_a, d_a), (z_b, d_b) in zip(zip(zs, differences), zip(zs[1:], differences[1:])):
        if d_a == 0.0 or d_a * d_b < 0.0:
            found.append(bisected(first, second, z_a, z_b) if d_a != 0.0 else z_a)
    return found


def bisected(first: Piece, second: Piece, z_a: float, z_b: float) -> float:
    sign_a = first.r_at(z_a) - second.r_at(z_a) > 0.0
    for _ in range(80):
        middle = (z_a + z_b) / 2.0
        if (first.r_at(middle) - second.r_at(middle) > 0.0) == sign_a:
            z_a = middle
        else:
            z_b = middle
    return (z_a + z_b) / 2.0


def r_range(piece: Piece) -> tuple[float, float]:
    """Smallest and largest radius of a piece (an arc piece may pass over its circle's top)."""
    low, high = sorted((piece.start_r, piece.end_r))
    if piece.centre is not None:
        over = piece.z0 <= piece.centre[0] <= piece.z1
        if over and piece.upper:
            high = piece.centre[1] + piece.radius
        elif over:
            low = piece.centre[1] - piece.radius
    return low, high


def overlapping_pairs(pieces: list[Piece]):
    """Pairs of pieces whose extents overlap (a sweep along Z): only they can cross."""
    ordered = sorted(pieces, key=lambda piece: piece.z0)
    ranges = {id(piece): r_range(piece) for piece in ordered}
    for index, first in enumerate(ordered):
        low, high = ranges[id(first)]
        for second in (ordered[k] for k in range(index + 1, len(ordered))):
            if second.z0 >= first.z1:
                break
            other_low, other_high = ranges[id(second)]
            if other_low <= high and low <= other_high:
                yield first, second


def breakpoints(pieces: list[Piece]) -> list[float]:
    zs = sorted({z for piece in pieces for z in (piece.z0, piece.z1)}
                | {z for a, b in overlapping_pairs(pieces) for z in crossings(a, b)})
    merged = [zs[0]]
    for z in zs[1:]:
        if z - merged[-1] > SAME_Z:
            merged.append(z)
    return merged


def top_pieces(pieces: list[Piece]) -> list[tuple[float, float, Piece | None]]:
    """(z_a, z_b, highest piece or None where nothing is drawn) between breakpoints."""
    zs = breakpoints(pieces)
    spans: list[tuple[float, float, Piece | None]] = []
    for z_a, z_b in zip(zs, zs[1:]):
        middle = (z_a + z_b) / 2.0
        covering = [piece for piece in pieces if piece.covers(middle)]
        top = max(covering, key=lambda piece: piece.r_at(middle)) if covering else None
        if spans and spans[-1][2] is top and top is not None:
            spans[-1] = (spans[-1][0], z_b, top)
        else:
            spans.append((z_a, z_b, top))
    return spans


def upper_envelope(segments: list[Segment], where: str) -> list[Segment]:
    """The half-profile of a side view, from its largest Z towards its smallest (the order a
    turning tool follows it); DxfError naming the gap when the outline is interrupted."""
    pieces = [piece for segment in segments for piece in pieces_of(segment)]
    if not pieces:
        raise DxfError(f"{where}: nothing is drawn above the centre line")
    spans = top_pieces(pieces)
    for z_a, z_b, top in spans:
        if top is None:
            raise DxfError(f"{where}: the outline has a gap between Z{z_a:.3f} and Z{z_b:.3f} (nothing "
                           "drawn there above the centre line); close the outline")
    path: list[Segment] = []
    for z_a, z_b, top in reversed(spans):
        assert top is not None   # a gap was refused above
        high = (z_b, top.r_at(z_b))
        if path and abs(path[-1].end[1] - high[1]) > END_MATCH_TOLERANCE_MM:
            path.append(Line(path[-1].end, high))   # a radial step where the highest line jumps
        path.append(top.segment(z_b, z_a))
    return joined(path)


def joined(path: list[Segment]) -> list[Segment]:
    """Each segment starts exactly where the previous one ends (steps are radial lines)."""
    result: list[Segment] = []
    for segment in path:
        if result and result[-1].end != segment.start:
            segment = moved_start(segment, result[-1].end)
        result.append(segment)
    return result


def moved_start(segment: Segment, start: tuple[float, float]) -> Segment:
    if isinstance(segment, Line):
        return Line(start, segment.end)
    return Arc(start, segment.end, segment.centre, segment.ccw)
