"""A turned part drawn whole, as a side view symmetric about its centre line → its upper
half-profile (issue 17), or the reason it is not one.

The axis is a straight, horizontal or vertical centre line (layers.LINE_ROLES) that runs
the length of one view of the profile layer, with that view on both sides of it; without
one, a drawing that is not a half-profile is tried for mirror symmetry about the middle
of its extents. The view is moved so the centre line is the axis (a vertical one turned to
lie along Z) and its outline above the axis is taken (envelope), once turnable has
found nothing a lathe cannot make from outside and inner_lines has found both halves
alike and every line inside the outline of a kind that leaves the turned surface as it is.
Outlines mirrored either side of a centre line that none of them reaches are a bored part's
section drawn without hatching, refused.
"""
from __future__ import annotations

import math
from collections import defaultdict

import msgspec

from .envelope import upper_envelope
from .geometry import Arc, Line, Segment
from .inner_lines import check_halves_agree, distance_to, frame_of, inner_lines_note
from .profile import END_MATCH_TOLERANCE_MM, Profile, bounds, merged_bounds, sweep
from .read import DxfError
from .turnable import check_no_bore, check_no_hidden_bore, check_no_prism, check_not_an_end_view, check_reaches_the_axis

ALONG_SLACK_MM = 1.0       # a centre line may stop this short of its view's ends
STRAIGHT = 1e-3            # |dy/dx| (or dx/dy) of a horizontal (vertical) centre line
SYMMETRY_SHARE = 0.97      # share of sample points whose mirror image lies on the drawing
SYMMETRY_TOLERANCE = 0.002  # of the drawing's size, at least END_MATCH_TOLERANCE_MM
SAMPLES_PER_SEGMENT = 12
GRID_CELLS = 100           # cells across the drawing for finding mirrored points
MAX_SYMMETRY_SEGMENTS = 5000   # a drawing of more pieces is no single part's side view


class Axis(msgspec.Struct, frozen=True):
    """A centre line in drawing coordinates (mm): horizontal at y = offset, or vertical at x = offset."""
    vertical: bool
    offset: float
    source: str     # how it was found, for the notes

    def point(self, p: tuple[float, float]) -> tuple[float, float]:
        """Drawing → (z, radius): along the line, and the distance from it."""
        return (p[1], p[0] - self.offset) if self.vertical else (p[0], p[1] - self.offset)

    def segment(self, s: Segment) -> Segment:
        if isinstance(s, Line):
            return Line(self.point(s.start), self.point(s.end), s.handle)
        # Swapping x and y (a vertical axis) mirrors the plane: arcs turn the other way.
        return Arc(self.point(s.start), self.point(s.end), self.point(s.centre), s.ccw != self.vertical, s.handle)


class Marks(msgspec.Struct):
    """What is drawn besides the outline, in mm: centre lines, hatching (boundary polygons) and
    hidden lines, from every layer."""
    centre_lines: list[Line] = []
    hatches: list[list[tuple[float, float]]] = []
    hidden: list[Segment] = []

    def near(self, view: list[Segment]) -> Marks:
        """The hatching and hidden lines within the view's extents."""
        box = merged_bounds(view)
        hatches = [p for p in self.hatches if boxes_touch(box, (min(x for x, _ in p), max(x for x, _ in p),
                                                                min(y for _, y in p), max(y for _, y in p)))]
        return Marks(self.centre_lines, hatches, [s for s in self.hidden if boxes_touch(box, bounds(s))])


class SideView(msgspec.Struct):
    profile: Profile
    notes: list[str]


def split_section(segments: list[Segment], centre_lines: list[Line], where: str) -> DxfError | None:
    """Outlines along a centre line on both sides of it, mirror images, none reaching it: the
    cut faces of a bored part's section drawn without hatching, the bore between them."""
    for line in centre_lines:
        axis = centre_axis(line)
        framed = [] if axis is None else [axis.segment(s) for view in views(segments)
                                          if alongside(axis, line, view) for s in view]
        if axis is not None and framed and min(bounds(s)[2] for s in framed) < 0.0 < max(bounds(s)[3] for s in framed) \
                and mirror_images(framed, where, axis.source):
            return split_section_refusal(framed, where, axis.source)
    return None


def mirror_images(framed: list[Segment], where: str, axis: str) -> bool:
    try:
        check_halves_agree(framed, upper_envelope(framed, where), where, axis)
    except DxfError:
        return False
    return True


def split_section_refusal(framed: list[Segment], where: str, axis: str) -> DxfError:
    z_min, z_max, _, _ = merged_bounds(framed)
    bore = 2 * min(min(abs(bounds(s)[2]), abs(bounds(s)[3])) for s in framed)
    return DxfError(f"{where}: the view about {axis} is drawn as outlines either side of it that leave "
                    f"Ø{bore:.3f} open along the axis from Z{z_min:.3f} to Z{z_max:.3f}: a section of a part "
                    "with a bore (drawn without hatching); cutting the bore needs internal turning, which is not "
                    "supported")


def alongside(axis: Axis, line: Line, view: list[Segment]) -> bool:
    """The view lies within the centre line's length, wholly on one side of it."""
    x_min, x_max, y_min, y_max = merged_bounds(view)
    along, across = ((y_min, y_max), (x_min, x_max)) if axis.vertical else ((x_min, x_max), (y_min, y_max))
    ends = sorted((line.start[1], line.end[1]) if axis.vertical else (line.start[0], line.end[0]))
    return (ends[0] - ALONG_SLACK_MM <= along[0] and along[1] <= ends[1] + ALONG_SLACK_MM
            and (across[0] >= axis.offset - END_MATCH_TOLERANCE_MM
                 or across[1] <= axis.offset + END_MATCH_TOLERANCE_MM))


def centre_axis(line: Line) -> Axis | None:
    (x0, y0), (x1, y1) = line.start, line.end
    if abs(y1 - y0) <= STRAIGHT * abs(x1 - x0):
        return Axis(False, (y0 + y1) / 2.0, f"the centre line {line.handle}")
    if abs(x1 - x0) <= STRAIGHT * abs(y1 - y0):
        return Axis(True, (x0 + x1) / 2.0, f"the centre line {line.handle}")
    return None


def views(segments: list[Segment]) -> list[list[Segment]]:
    """The drawing's separate views: entities whose extents touch, grouped, and groups lying
    within another group's extents (holes inside an outline) joined to it."""
    by_handle: dict[str, list[Segment]] = {}
    for number, segment in enumerate(segments):
        by_handle.setdefault(segment.handle or f"#{number}", []).append(segment)
    groups = joined_groups(list(by_handle.values()), boxes_touch)
    return joined_groups(groups, lambda a, b: box_within(a, b) or box_within(b, a))


def joined_groups(groups: list[list[Segment]], related) -> list[list[Segment]]:
    """Groups joined where `related` holds for their extents (union-find)."""
    boxes = [merged_bounds(group) for group in groups]
    parent = list(range(len(groups)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    by_x = sorted(range(len(groups)), key=lambda i: boxes[i][0])
    for place, i in enumerate(by_x):   # only extents overlapping along X can be related: a sweep
        for j in (by_x[k] for k in range(place + 1, len(by_x))):
            if boxes[j][0] > boxes[i][1] + END_MATCH_TOLERANCE_MM:
                break
            if related(boxes[i], boxes[j]):
                parent[root(i)] = root(j)
    found: dict[int, list[Segment]] = {}
    for i, group in enumerate(groups):
        found.setdefault(root(i), []).extend(group)
    return list(found.values())


def box_within(inner, outer) -> bool:
    return outer[0] <= inner[0] and inner[1] <= outer[1] and outer[2] <= inner[2] and inner[3] <= outer[3]


def boxes_touch(a, b, slack: float = END_MATCH_TOLERANCE_MM) -> bool:
    return a[0] <= b[1] + slack and b[0] <= a[1] + slack and a[2] <= b[3] + slack and b[2] <= a[3] + slack


def runs_through(axis: Axis, line: Line, view: list[Segment]) -> bool:
    """The centre line spans the view along its length and the view lies on both sides of it."""
    x_min, x_max, y_min, y_max = merged_bounds(view)
    along, across = ((y_min, y_max), (x_min, x_max)) if axis.vertical else ((x_min, x_max), (y_min, y_max))
    ends = sorted((line.start[1], line.end[1]) if axis.vertical else (line.start[0], line.end[0]))
    return (ends[0] - ALONG_SLACK_MM <= along[0] and along[1] <= ends[1] + ALONG_SLACK_MM
            and across[0] < axis.offset - END_MATCH_TOLERANCE_MM and across[1] > axis.offset + END_MATCH_TOLERANCE_MM)


def centred_views(segments: list[Segment], centre_lines: list[Line]) -> list[tuple[Axis, list[Segment]]]:
    axes = [line for line in centre_lines if centre_axis(line) is not None]
    if not axes:
        return []
    found = []
    for view in views(segments):
        for line in axes:
            axis = centre_axis(line)
            if axis is not None and runs_through(axis, line, view):
                found.append((axis, view))
    return found


def samples(segment: Segment) -> list[tuple[float, float]]:
    if isinstance(segment, Line):
        (x0, y0), (x1, y1) = segment.start, segment.end
        return [(x0 + (x1 - x0) * k / SAMPLES_PER_SEGMENT, y0 + (y1 - y0) * k / SAMPLES_PER_SEGMENT)
                for k in range(SAMPLES_PER_SEGMENT + 1)]
    (cx, cy), radius, turn = segment.centre, segment.radius, sweep(segment)
    begin = math.atan2(segment.start[1] - cy, segment.start[0] - cx)
    sense = 1.0 if segment.ccw else -1.0
    return [(cx + radius * math.cos(begin + sense * turn * k / SAMPLES_PER_SEGMENT),
             cy + radius * math.sin(begin + sense * turn * k / SAMPLES_PER_SEGMENT))
            for k in range(SAMPLES_PER_SEGMENT + 1)]


class NearIndex:
    """Segments by grid cell of their extents, to find what lies near a point quickly."""

    def __init__(self, segments: list[Segment], cell: float):
        self.cell, self.cells = cell, defaultdict(list)
        for segment in segments:
            z_min, z_max, r_min, r_max = bounds(segment)
            for i in range(self.key(z_min), self.key(z_max) + 1):
                for j in range(self.key(r_min), self.key(r_max) + 1):
                    self.cells[(i, j)].append(segment)

    def key(self, value: float) -> int:
        return math.floor(value / self.cell)

    def near(self, point: tuple[float, float], tolerance: float) -> bool:
        cells = {(self.key(point[0] + dx), self.key(point[1] + dy)) for dx in (-tolerance, tolerance)
                 for dy in (-tolerance, tolerance)}
        return any(distance_to(point, s) <= tolerance for cell in cells for s in self.cells.get(cell, ()))


def symmetry_axis(segments: list[Segment]) -> Axis | None:
    """A horizontal or vertical line through the middle of the drawing that mirrors it onto
    itself (SYMMETRY_SHARE of its sample points), else None."""
    if len(segments) > MAX_SYMMETRY_SEGMENTS:
        return None
    x_min, x_max, y_min, y_max = merged_bounds(segments)
    size = max(x_max - x_min, y_max - y_min)
    tolerance = max(END_MATCH_TOLERANCE_MM, SYMMETRY_TOLERANCE * size)
    index = NearIndex(segments, max(size / GRID_CELLS, tolerance))
    points = [p for segment in segments for p in samples(segment)]
    middle_y, middle_x = (y_min + y_max) / 2.0, (x_min + x_max) / 2.0
    for axis in (Axis(False, middle_y, f"the line of symmetry at drawing Y {middle_y:.3f}"),
                 Axis(True, middle_x, f"the line of symmetry at drawing X {middle_x:.3f}")):
        mirrored = [((2 * axis.offset - x, y) if axis.vertical else (x, 2 * axis.offset - y)) for x, y in points]
        near = sum(1 for p in mirrored if index.near(p, tolerance))
        if near >= SYMMETRY_SHARE * len(points):
            return axis
    return None


def side_view(axis: Axis, view: list[Segment], marks: Marks, where: str) -> SideView:
    """The upper half-profile of one view about its axis, or DxfError with what it is instead."""
    framed = [axis.segment(s) for s in view]
    check_not_an_end_view(framed, where)
    check_reaches_the_axis(framed, where, axis.source)
    outline = upper_envelope(framed, where)
    z_min, z_max = outline[-1].end[0], outline[0].start[0]
    check_no_bore([[axis.point(p) for p in polygon] for polygon in marks.hatches], z_min, z_max, where)
    check_no_hidden_bore([axis.segment(s) for s in marks.hidden], outline, where)
    check_no_prism(framed, outline, where)
    check_symmetric_about(axis, view, framed, outline, where)
    open_faces = open_radii(framed, outline)
    inner = inner_lines_note(framed, frame_of(framed, outline, open_faces), where)
    profile = Profile(outline, True, merged_bounds(outline))
    turn = " (a vertical centre line: drawing Y is Z)" if axis.vertical else ""
    notes = [f"{where} is a side view: its half above {axis.source}{turn} is the profile, moved so that line is "
             f"the axis; {len({s.handle for s in framed})} entities drawn in all", inner]
    return SideView(profile, notes + open_face_notes(open_faces, where))


def check_symmetric_about(axis: Axis, view: list[Segment], framed: list[Segment], outline: list[Segment],
                          where: str) -> None:
    """A centre line is the axis only if the view is the same on both sides of it: a dash-dot
    line beside the symmetry (a pitch line, a leader) is refused naming both lines."""
    try:
        check_halves_agree(framed, outline, where, axis.source)
    except DxfError as refusal:
        other = symmetry_axis(view)
        if other is None or (other.vertical == axis.vertical and abs(other.offset - axis.offset)
                             <= END_MATCH_TOLERANCE_MM):
            raise
        raise DxfError(f"{where}: {axis.source} (drawing {'X' if axis.vertical else 'Y'} {axis.offset:.3f}) is not "
                       f"the view's axis: the view is symmetric about {other.source} instead; put the centre line "
                       "on the part's axis") from refusal


def open_radii(framed: list[Segment], outline: list[Segment]) -> dict[float, float]:
    """Each end face's Z → the smallest radius it is drawn down to (0: to the axis)."""
    found = {}
    for face in (outline[0].start[0], outline[-1].end[0]):
        at_face = [s for s in framed if isinstance(s, Line) and max(s.start[1], s.end[1]) > 0.0
                   and abs(s.start[0] - face) <= END_MATCH_TOLERANCE_MM >= abs(s.end[0] - face)]
        found[face] = min((max(min(s.start[1], s.end[1]), 0.0) for s in at_face), default=0.0)
    return found


def open_face_notes(open_faces: dict[float, float], where: str) -> list[str]:
    """An end face drawn only part of the way to the axis leaves a slot or recess open there,
    which the job does not make: it faces the end to the axis."""
    return [f"{where}: the end face at Z{face:.3f} is drawn down to radius {lowest:.3f} only; the slot or "
            f"recess it leaves open (Ø{2 * lowest:.3f} seen from the side) is not a turned surface and "
            "is not made: the job faces that end to the axis"
            for face, lowest in open_faces.items() if lowest > END_MATCH_TOLERANCE_MM]


def side_view_of(segments: list[Segment], marks: Marks, layer: str) -> SideView | None:
    """The side view a centre line runs through, None when no centre line runs through a view;
    DxfError when only views along the axis are found or two side views compete."""
    candidates = centred_views(segments, marks.centre_lines)
    if not candidates:
        split = split_section(segments, marks.centre_lines, f"layer {layer}")
        if split is not None:
            raise split
        return None
    found, refusals = [], []
    for axis, view in candidates:
        try:
            found.append(side_view(axis, view, marks.near(view), f"layer {layer}"))
        except DxfError as refusal:
            refusals.append(refusal)
    if len(found) == 1:
        others = len(views(segments)) - 1
        found[0].notes.extend([f"layer {layer}: {others} other view(s) left out"] if others else [])
        return found[0]
    if found:
        raise DxfError(f"layer {layer} has {len(found)} side views about centre lines; keep one of them on the "
                       "profile layer (or move the others to another layer)")
    raise max(refusals, key=telling)


# Which refusal says most about a drawing whose views all failed: a view along the axis is the
# least telling (most drawings have one), a bore or a prism in a side view the most.
REFUSAL_WEIGHTS = (("a view along the axis", 0), ("not a turned part", 1), ("has a gap", 2))


def telling(refusal: DxfError) -> int:
    text = str(refusal)
    return next((weight for words, weight in REFUSAL_WEIGHTS if words in text), 3)
