"""A half-profile drawn with its axis vertical (issue 27): the revolve convention of OpenSCAD
(`rotate_extrude` turns the shape right of drawing X 0 about the drawing Y axis) and FreeCAD
(a sketch revolved about its vertical axis): drawing X is the radius, the axis is the line
drawing X = 0, the part runs along drawing Y.

Such a drawing is read by swapping drawing X and Y: machine Z is drawing Y, so the drawing's
upper (+Y) end becomes the part's front (the largest Z, where the tool starts), and the
radius is drawing X. The swap mirrors the plane, so every arc turns the other way.

It is tried only where the seed-000 reading (the axis along drawing Y 0) found no profile and
the drawing lies right of drawing X 0. Read that way, the profile must reach the axis (X 0);
an outline that runs along some other vertical line over the drawing's height has its axis
there and is refused: the user rotates (and moves) the drawing, the engine does not guess.
"""
from __future__ import annotations

import msgspec

from .geometry import Arc, Line, Point, Segment
from .profile import END_MATCH_TOLERANCE_MM, Profile, chain_segments, find_profile, merged_bounds
from .read import DxfError

# A vertical line of the outline that spans at least this share of the drawing's height is the
# edge a revolve turns about (the axis drawn as the profile's closing edge).
AXIS_EDGE_SHARE = 0.9
ROTATE = "the axis looks vertical: rotate the drawing so the part's axis lies along drawing Y 0"


class VerticalReading(msgspec.Struct, frozen=True):
    profile: Profile
    notes: list[str]


def swap(point: Point) -> Point:
    return (point[1], point[0])


def swapped(segment: Segment) -> Segment:
    """Drawing (x, y) → (y, x): a mirror image, so an arc's sense flips."""
    if isinstance(segment, Line):
        return Line(swap(segment.start), swap(segment.end), segment.handle)
    return Arc(swap(segment.start), swap(segment.end), swap(segment.centre), not segment.ccw, segment.handle)


def vertical_edge(segments: list[Segment], x: float, height: float, across: int = 1) -> bool:
    """A line along coordinate 1 - across = x (drawing X, or Z in machine coordinates) spanning
    most (AXIS_EDGE_SHARE) of the height along coordinate `across`."""
    tolerance, along = END_MATCH_TOLERANCE_MM, 1 - across
    return any(isinstance(s, Line) and abs(s.start[along] - x) <= tolerance and abs(s.end[along] - x) <= tolerance
               and abs(s.end[across] - s.start[across]) >= AXIS_EDGE_SHARE * height for s in segments)


def vertical_profile(segments: list[Segment], layer: str) -> VerticalReading | None:
    """The profile read with a vertical axis at drawing X 0; None when the drawing does not lie
    right of X 0 or does not read so either (the caller's own refusal stands); DxfError naming
    the vertical axis when the outline turns about another vertical line or reads no profile."""
    x_min, _, y_min, y_max = merged_bounds(segments)
    if x_min < -END_MATCH_TOLERANCE_MM:
        return None
    edge = vertical_edge(segments, x_min, y_max - y_min)
    try:
        profile = find_profile(chain_segments([swapped(s) for s in segments]), layer=layer)
    except DxfError as refusal:
        if edge and x_min <= END_MATCH_TOLERANCE_MM:
            raise DxfError(f"layer {layer}: {ROTATE}; read with the axis at drawing X 0: {refusal}") from None
        return None
    if profile.bounds[2] > END_MATCH_TOLERANCE_MM:
        if edge:
            raise DxfError(f"layer {layer}: {ROTATE} (its outline turns about drawing X {x_min:g}, not X 0)")
        return None
    return VerticalReading(profile, [
        f"layer {layer}: the axis is vertical (drawing X is the radius, the axis the line X 0, as OpenSCAD "
        "and FreeCAD revolve): the drawing was turned into the lathe's Z–X plane, its upper (+Y) end the "
        f"front (Z{profile.bounds[1]:g}); turn the drawing over if the other end is the front"])


def vertical_doubt(profile: Profile, layer: str, other_reading: bool) -> list[str]:
    """A note when a drawing read with its axis along drawing Y 0 could as well be a half-profile
    about the vertical line X 0: it lies right of X 0 and an edge along X 0 spans its whole height
    down to Y 0 (a revolve sketch of OpenSCAD or FreeCAD looks so). The seed-000 reading stands."""
    z_min, _, r_min, r_max = profile.bounds
    tolerance = END_MATCH_TOLERANCE_MM
    if other_reading or profile.mirrored or abs(z_min) > tolerance or r_min > tolerance:
        return []
    if not vertical_edge([*profile.segments, *profile.closing_segments()], 0.0, r_max - r_min, across=1):
        return []
    return [f"layer {layer}: read with the axis along drawing Y 0 (radius = drawing Y); it lies right of "
            "drawing X 0 with an edge along X 0 over its whole height, as a half-profile about a vertical "
            "axis (OpenSCAD, FreeCAD) would: if that is its axis, rotate the drawing"]
