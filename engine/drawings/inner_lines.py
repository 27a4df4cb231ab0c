"""What a side view shows besides its outline, and whether its two halves agree (issue 17).

A turned part is the same above and below its axis, so a side view whose halves differ does
not say which part to make. Inside the outline, a side view shows lines that do not change
the turned surface (INNER_LINE_KINDS: an edge across the part, a thread's root, an end face
and the slot or recess an open end face leaves), but a section drawn without hatching shows a
bore with the same solid lines. A line inside the outline is left out only when it is
recognised as one of those kinds; a line along the axis from an end face is a bore, anything
else is refused by handle. Coordinates are machine (z, radius) about the view's axis, in mm.
"""
from __future__ import annotations

import bisect
import math
from collections import Counter
from collections.abc import Callable

import msgspec

from .envelope import SAME_Z, pieces_of, upper_envelope
from .geometry import Arc, Line, Segment
from .profile import END_MATCH_TOLERANCE_MM, merged_bounds, sweep
from .read import DxfError

# A thread's root line lies under its outer diameter at no less than this share of it: the
# minor diameter of ISO metric threads (ISO 68-1, d3 = d - 1.2269 P) is 0.69 d for the coarsest
# (M1) and more for larger and fine ones; drawings show it at 0.7 to 0.9 d. A line deeper
# under the outline is no thread root (it may be a bore's wall).
THREAD_ROOT_SHARE = 0.65
HALVES_TOLERANCE = 0.002   # of the view's size, at least END_MATCH_TOLERANCE_MM
HALVES_SAMPLES = 4         # Z positions compared between two successive ends of outline pieces
NAMED_HANDLES = 6
MIRROR_OVERLAP = 0.9       # share of a thread root's length its mirror image below the axis covers


class Frame(msgspec.Struct, frozen=True):
    """A side view about its axis: its outline (upper envelope) and where its end faces are."""
    outline: list[Segment]
    z_min: float
    z_max: float
    open_radius: dict[float, float]   # end face Z → the radius it is drawn down to
    recess: frozenset[int]            # id() of the lines bounding an open end's slot or recess
    radii: Radii
    steps: list[Segment]              # the outline's radial lines (shoulders)
    axial: list[Segment]              # the view's lines along the axis

    def radius(self, z: float) -> float:
        return self.radii.at(z)

    def on_outline(self, point: tuple[float, float]) -> bool:
        """Within END_MATCH_TOLERANCE_MM of the outline or its mirror image below the axis: of a
        shoulder, or of the outline's radius somewhere within that distance along Z."""
        z, r, near = point[0], abs(point[1]), END_MATCH_TOLERANCE_MM
        if any(distance_to((z, r), step) <= near for step in self.steps):
            return True
        radii = [self.radius(z - near), self.radius(z), self.radius(z + near)]
        return min(radii) - near <= r <= max(radii) + near


class Radii:
    """An outline's radius along Z: its pieces by where they start, found by bisection (an
    envelope's pieces follow one another along Z, so only the last two starting before z can
    cover it)."""

    def __init__(self, outline: list[Segment]):
        self.pieces = sorted((piece for s in outline for piece in pieces_of(s)), key=lambda piece: piece.z0)
        self.starts = [piece.z0 for piece in self.pieces]

    def at(self, z: float) -> float:
        """The largest radius at z (0 outside the outline)."""
        found = bisect.bisect_right(self.starts, z + SAME_Z)
        return max((piece.r_at(z) for piece in self.pieces[max(0, found - 2):found] if piece.covers(z)), default=0.0)


def distance_to(point: tuple[float, float], segment: Segment) -> float:
    if isinstance(segment, Line):
        (z0, r0), (z1, r1) = segment.start, segment.end
        dz, dr = z1 - z0, r1 - r0
        squared = dz * dz + dr * dr
        t = 0.0 if squared == 0 else max(0.0, min(1.0, ((point[0] - z0) * dz + (point[1] - r0) * dr) / squared))
        return math.dist(point, (z0 + t * dz, r0 + t * dr))
    probe = Arc(segment.start, point, segment.centre, segment.ccw)
    if sweep(probe) <= sweep(segment):
        return abs(math.dist(point, segment.centre) - segment.radius)
    return min(math.dist(point, segment.start), math.dist(point, segment.end))


def points_of(segment: Segment, count: int = 8) -> list[tuple[float, float]]:
    if isinstance(segment, Line):
        (z0, r0), (z1, r1) = segment.start, segment.end
        return [(z0 + (z1 - z0) * k / count, r0 + (r1 - r0) * k / count) for k in range(count + 1)]
    (cz, cr), radius, turn = segment.centre, segment.radius, sweep(segment)
    begin = math.atan2(segment.start[1] - cr, segment.start[0] - cz)
    sense = 1.0 if segment.ccw else -1.0
    return [(cz + radius * math.cos(begin + sense * turn * k / count),
             cr + radius * math.sin(begin + sense * turn * k / count))
            for k in range(count + 1)]


def is_radial(segment: Segment) -> bool:
    return isinstance(segment, Line) and abs(segment.start[0] - segment.end[0]) <= END_MATCH_TOLERANCE_MM


def is_axial(segment: Segment) -> bool:
    return isinstance(segment, Line) and abs(segment.start[1] - segment.end[1]) <= END_MATCH_TOLERANCE_MM \
        and abs(segment.start[0] - segment.end[0]) > END_MATCH_TOLERANCE_MM


def on_the_outline(segment: Segment, frame: Frame) -> bool:
    """Every point on the outline, above or (mirrored) below the axis."""
    return all(frame.on_outline(p) for p in points_of(segment))


def an_end_face(segment: Segment, frame: Frame) -> bool:
    return is_radial(segment) and any(abs(segment.start[0] - z) <= END_MATCH_TOLERANCE_MM
                                      for z in (frame.z_min, frame.z_max))


def an_edge_across(segment: Segment, frame: Frame) -> bool:
    """A radial line from the outline to the outline (a shoulder, a chamfer's edge, a thread's end)."""
    return is_radial(segment) and frame.on_outline(segment.start) and frame.on_outline(segment.end)


def a_thread_root(segment: Segment, frame: Frame) -> bool:
    """A line along the axis close under the outline all along (THREAD_ROOT_SHARE), not from end
    face to end face (that is a thin-walled bore's wall: a thread ends before a face or shoulder)."""
    ends = sorted((segment.start[0], segment.end[0]))
    through = ends[0] <= frame.z_min + END_MATCH_TOLERANCE_MM and ends[1] >= frame.z_max - END_MATCH_TOLERANCE_MM
    return is_axial(segment) and not through and mirrored_in(segment, frame.axial) and all(
        THREAD_ROOT_SHARE * frame.radius(z) <= abs(r) < frame.radius(z) + END_MATCH_TOLERANCE_MM
        for z, r in points_of(segment))


def mirrored_in(line: Segment, axial: list[Segment]) -> bool:
    """A line along the axis at the same radius on the other side, over most (MIRROR_OVERLAP)
    of its length: a thread's root shows on both sides of the axis."""
    z0, z1 = sorted((line.start[0], line.end[0]))
    for other in axial:
        o0, o1 = sorted((other.start[0], other.end[0]))
        if abs(other.start[1] + line.start[1]) <= END_MATCH_TOLERANCE_MM \
                and min(z1, o1) - max(z0, o0) >= MIRROR_OVERLAP * (z1 - z0):
            return True
    return False


def in_an_open_end(segment: Segment, frame: Frame) -> bool:
    """A line of the slot or recess an end face drawn only part of the way to the axis leaves
    open (a screw head's slot): the job faces that end to the axis and says so."""
    return id(segment) in frame.recess


def frame_of(framed: list[Segment], outline: list[Segment], open_radius: dict[float, float]) -> Frame:
    recess = [line for face, radius in open_radius.items() if radius > END_MATCH_TOLERANCE_MM
              for line in recess_lines(framed, face, radius)]
    steps = [s for s in outline if is_radial(s)]
    return Frame(outline, outline[-1].end[0], outline[0].start[0], open_radius, frozenset(map(id, recess)),
                 Radii(outline), steps, [s for s in framed if is_axial(s)])


def recess_lines(framed: list[Segment], face: float, radius: float) -> list[Segment]:
    """The lines within the open radius that join, end to end, the open face's edges (face, ±radius):
    the recess's walls and bottom, not a cavity elsewhere along the part."""
    inside = [s for s in framed if all(abs(r) <= radius + END_MATCH_TOLERANCE_MM for _, r in points_of(s))]
    reached, found = [(face, radius), (face, -radius)], []
    grown = True
    while grown:
        joined = [s for s in inside if s not in found and any(math.dist(p, q) <= END_MATCH_TOLERANCE_MM
                                                                  for p in (s.start, s.end) for q in reached)]
        found += joined
        reached += [p for s in joined for p in (s.start, s.end)]
        grown = bool(joined)
    return found


INNER_LINE_KINDS: tuple[tuple[str, Callable[[Segment, Frame], bool]], ...] = (
    ("outline", on_the_outline),
    ("end faces", an_end_face),
    ("edges across the part", an_edge_across),
    ("thread roots", a_thread_root),
    ("an open end's slot or recess", in_an_open_end),
)


def kind_of(segment: Segment, frame: Frame) -> str | None:
    return next((name for name, recognised in INNER_LINE_KINDS if recognised(segment, frame)), None)


def inner_lines_note(framed: list[Segment], frame: Frame, where: str) -> str:
    """A note counting the lines left out by kind; DxfError for a line no kind explains."""
    found = [(segment, kind_of(segment, frame)) for segment in framed]
    kinds = Counter(kind for _, kind in found)
    unplaced = [segment for segment, kind in found if kind is None]
    if unplaced:
        raise unplaced_refusal(unplaced, frame, where)
    inside = "; ".join(f"{name}: {count}" for name, count in kinds.items() if name != "outline")
    return (f"{where}: the lines inside its outline are not turned surfaces and are left out "
            f"({inside or 'none'})")


def unplaced_refusal(unplaced: list[Segment], frame: Frame, where: str) -> DxfError:
    """A line along the axis from an end face is a bore's wall; other lines are named by handle."""
    for line in unplaced:
        z0, z1 = sorted((line.start[0], line.end[0]))
        from_face = abs(z0 - frame.z_min) <= END_MATCH_TOLERANCE_MM or abs(z1 - frame.z_max) <= END_MATCH_TOLERANCE_MM
        if is_axial(line) and from_face:
            return DxfError(f"{where}: solid lines show a bore Ø{2 * abs(line.start[1]):.3f} from Z{z0:.3f} to "
                            f"Z{z1:.3f}, from the end face (a section drawn without hatching, handle {line.handle}); "
                            "cutting it needs internal turning, which is not supported")
    handles = list(dict.fromkeys(s.handle or "?" for s in unplaced))
    named = ", ".join(handles[:NAMED_HANDLES]) + (", …" if len(handles) > NAMED_HANDLES else "")
    return DxfError(f"{where}: lines inside the outline that the reader cannot place: {named} (no edge across "
                    "the part, thread root or end face; they may bound a cavity); nothing made")


def check_halves_agree(framed: list[Segment], outline: list[Segment], where: str, axis: str) -> None:
    """The outline below the axis, mirrored, is the one above it (within HALVES_TOLERANCE)."""
    mirrored = [mirror(s) for s in framed]
    try:
        lower = upper_envelope(mirrored, where)
    except DxfError:
        raise DxfError(f"{where}: below {axis} the view is not drawn whole (its outline there has a gap), "
                       "above it is; a turned part is the same on both sides: correct the drawing") from None
    x_min, x_max, y_min, y_max = merged_bounds(framed)
    tolerance = max(END_MATCH_TOLERANCE_MM, HALVES_TOLERANCE * max(x_max - x_min, y_max - y_min))
    differ = halves_differ(outline, lower, tolerance)
    if differ:
        (z_a, _, upper_r, lower_r), z_b = differ[0], differ[-1][1]
        raise DxfError(f"{where}: its halves above and below {axis} differ from Z{z_a:.3f} to Z{z_b:.3f} "
                       f"(radius {upper_r:.3f} above, {lower_r:.3f} below after Z{z_a:.3f}); a "
                       "turned part is the same on both sides, the drawing does not say which to make: correct it")


def mirror(segment: Segment) -> Segment:
    def flip(p):
        return p[0], -p[1]

    if isinstance(segment, Line):
        return Line(flip(segment.start), flip(segment.end), segment.handle)
    return Arc(flip(segment.start), flip(segment.end), flip(segment.centre), not segment.ccw, segment.handle)


def halves_differ(upper: list[Segment], lower: list[Segment],
                  tolerance: float) -> list[tuple[float, float, float, float]]:
    """(z from, z to, upper radius, lower radius) of the spans where the two outlines are further
    apart than tolerance, sampled between each two successive ends of their pieces (where neither
    has a corner), a half drawn shorter counting as radius 0 beyond its end."""
    ends = sorted({z for s in upper + lower for z in (s.start[0], s.end[0])})
    radii = (Radii(upper), Radii(lower))
    found = []
    for z_a, z_b in zip(ends, ends[1:]):
        apart = [(above, below) for above, below in sampled_radii(*radii, z_a, z_b)
                 if abs(above - below) > tolerance]
        found.extend([(z_a, z_b, *apart[0])] if apart else [])
    return found


def sampled_radii(upper: Radii, lower: Radii, z_a: float, z_b: float) -> list[tuple[float, float]]:
    zs = [z_a + (z_b - z_a) * (k + 0.5) / HALVES_SAMPLES for k in range(HALVES_SAMPLES)]
    return [(upper.at(z), lower.at(z)) for z in zs]
