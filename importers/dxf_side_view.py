"""A turned part drawn whole, as a side view symmetric about its centre line → its upper
half-profile (issue 17), or the reason it is not one.

The axis is a straight, horizontal or vertical centre line (dxf_layers.LINE_ROLES) that runs
the length of one view of the profile layer, with that view on both sides of it; without
one, a drawing that is not a half-profile is tried for mirror symmetry about the middle
of its extents. The view is moved so the centre line is the axis (a vertical one turned to
lie along Z) and its outline above the axis is taken (dxf_envelope). Before that, what a
lathe cannot make from outside is refused by name (VIEW_CHECKS): a view along the axis,
a plate's holes, a section whose hatching leaves a bore, a prism such as a hexagon head.
"""
from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass

from .dxf_envelope import upper_envelope
from .dxf_geometry import Arc, Line, Segment
from .dxf_profile import END_MATCH_TOLERANCE_MM, Profile, bounds, merged_bounds, sweep
from .dxf_read import DxfError

ALONG_SLACK_MM = 1.0       # a centre line may stop this short of its view's ends
STRAIGHT = 1e-3            # |dy/dx| (or dx/dy) of a horizontal (vertical) centre line
SYMMETRY_SHARE = 0.97      # share of sample points whose mirror image lies on the drawing
SYMMETRY_TOLERANCE = 0.002  # of the drawing's size, at least END_MATCH_TOLERANCE_MM
SAMPLES_PER_SEGMENT = 12
GRID_CELLS = 100           # cells across the drawing for finding mirrored points
MAX_SYMMETRY_SEGMENTS = 5000   # a drawing of more pieces is no single part's side view
HATCH_SAMPLES = 200
# Interior edges along the whole length of a cylinder-like span, as a share of its outline
# radius, and what a side view with them shows: the faces of a prism, not a turned surface.
PRISM_EDGES = ((0.5, "a hexagon seen across its corners (edges at ±e/4 inside its outline ±e/2)"),
               (0.0, "a hexagon seen across its flats, or a square across its corners (an edge on the centre line)"))
PRISM_SHARE_TOLERANCE = 0.03


@dataclass(frozen=True)
class Axis:
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


@dataclass
class SideView:
    profile: Profile
    notes: list[str]


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
    for axis in (Axis(False, (y_min + y_max) / 2.0, "geometric symmetry"),
                 Axis(True, (x_min + x_max) / 2.0, "geometric symmetry")):
        mirrored = [((2 * axis.offset - x, y) if axis.vertical else (x, 2 * axis.offset - y)) for x, y in points]
        near = sum(1 for p in mirrored if index.near(p, tolerance))
        if near >= SYMMETRY_SHARE * len(points):
            return axis
    return None


def check_not_an_end_view(framed: list[Segment], where: str) -> None:
    """A circle (or an arc of more than half a turn) centred on the axis: the view looks along the axis."""
    turned: dict[tuple, float] = {}
    for s in framed:
        if isinstance(s, Arc) and abs(s.centre[1]) <= END_MATCH_TOLERANCE_MM:
            turn_key = (s.handle, round(s.centre[0], 3), round(s.radius, 3))
            turned[turn_key] = turned.get(turn_key, 0.0) + sweep(s)
    circles = sorted({2 * radius for (_, _, radius), turn in turned.items() if turn > math.pi + 1e-6})
    if circles:
        shown = ", ".join(f"Ø{d:g}" for d in circles[:4])
        raise DxfError(f"{where} shows circles centred on its centre line ({shown}): a view along the axis, "
                       "not a side view; draw the side view of the part (or its half-profile)")


def check_reaches_the_axis(framed: list[Segment], where: str) -> None:
    """A turned part's side view has lines across the axis (its end faces); a plate's holes do not."""
    if any(bounds(s)[2] < -END_MATCH_TOLERANCE_MM and bounds(s)[3] > END_MATCH_TOLERANCE_MM
           or max(abs(s.start[1]), abs(s.end[1])) <= END_MATCH_TOLERANCE_MM for s in framed):
        return
    handles = len({s.handle for s in framed})
    raise DxfError(f"{where}: nothing drawn crosses or meets its centre line; it is {handles} separate outline(s) "
                   "on either side (holes of a plate, a flat part), not a turned part")


def lowest_hatched(polygons: list[list[tuple[float, float]]], z: float) -> tuple[float | None, float | None]:
    """The smallest radius of hatched material at z above and below the axis (None: no hatch)."""
    crossings = sorted(r0 + (z - z0) * (r1 - r0) / (z1 - z0) for polygon in polygons
                       for (z0, r0), (z1, r1) in zip(polygon, polygon[1:] + polygon[:1])
                       if (z0 <= z < z1) or (z1 <= z < z0))
    inside = list(zip(crossings[0::2], crossings[1::2]))
    above = [max(low, 0.0) for low, high in inside if high > 0.0]
    below = [max(-high, 0.0) for low, high in inside if low < 0.0]
    return (min(above) if above else None), (min(below) if below else None)


def check_no_bore(polygons: list[list[tuple[float, float]]], z_min: float, z_max: float, where: str) -> None:
    """In a section the hatching is the material: where it stops short of the axis, a bore is."""
    if not polygons:
        return
    bored = []
    for k in range(1, HATCH_SAMPLES):
        z = z_min + (z_max - z_min) * k / HATCH_SAMPLES
        lows = [low for low in lowest_hatched(polygons, z) if low is not None]
        if lows and min(lows) > END_MATCH_TOLERANCE_MM:
            bored.append((z, min(lows)))
    if bored:
        diameter = 2 * min(radius for _, radius in bored)
        through = len(bored) == HATCH_SAMPLES - 1
        span = (f"through the whole part (Z{z_min:.3f} to Z{z_max:.3f})" if through
                else f"from Z{bored[0][0]:.3f} to Z{bored[-1][0]:.3f}")
        raise DxfError(f"{where}: the section shows a bore Ø{diameter:.3f} {span} (its hatching stops short of "
                       "the axis); cutting it needs internal turning, which is not supported")


def check_no_prism(framed: list[Segment], outline: list[Segment], where: str) -> None:
    """Edges along the whole length of a constant-radius span, at a radius a prism shows."""
    spans = [(min(s.start[0], s.end[0]), max(s.start[0], s.end[0]), s.start[1]) for s in outline
             if isinstance(s, Line) and abs(s.start[1] - s.end[1]) <= END_MATCH_TOLERANCE_MM
             and abs(s.start[0] - s.end[0]) > END_MATCH_TOLERANCE_MM]
    for s in framed:
        if not isinstance(s, Line) or abs(s.start[1] - s.end[1]) > END_MATCH_TOLERANCE_MM or s.start[1] < -END_MATCH_TOLERANCE_MM:
            continue
        z0, z1, radius = min(s.start[0], s.end[0]), max(s.start[0], s.end[0]), s.start[1]
        for a, b, outer in spans:
            if abs(z0 - a) <= 5 * END_MATCH_TOLERANCE_MM and abs(z1 - b) <= 5 * END_MATCH_TOLERANCE_MM \
                    and radius < outer - END_MATCH_TOLERANCE_MM:
                check_prism_share(radius, outer, a, b, where)


def check_prism_share(radius: float, outer: float, a: float, b: float, where: str) -> None:
    for share, shows in PRISM_EDGES:
        if abs(radius / outer - share) <= PRISM_SHARE_TOLERANCE:
            raise DxfError(f"{where}: the part from Z{a:.3f} to Z{b:.3f} is not a turned surface: its side view has "
                           f"edges at ±{radius:.3f} along its whole length inside its outline ±{outer:.3f}, as "
                           f"{shows}; a lathe cannot make it as drawn")


def side_view(axis: Axis, view: list[Segment], polygons, where: str) -> SideView:
    """The upper half-profile of one view about its axis, or DxfError with what it is instead."""
    framed = [axis.segment(s) for s in view]
    check_not_an_end_view(framed, where)
    check_reaches_the_axis(framed, where)
    outline = upper_envelope(framed, where)
    z_min, z_max = outline[-1].end[0], outline[0].start[0]
    check_no_bore([[axis.point(p) for p in polygon] for polygon in polygons], z_min, z_max, where)
    check_no_prism(framed, outline, where)
    profile = Profile(outline, True, merged_bounds(outline))
    inside = len({s.handle for s in framed})
    turn = " (a vertical centre line: drawing Y is Z)" if axis.vertical else ""
    notes = [f"{where} is a side view: its half above {axis.source}{turn} is the profile, moved so that line is "
             f"the axis; the lines inside its outline (edges, thread roots, slots; {inside} entities drawn in all) "
             "are not turned surfaces and are left out"]
    return SideView(profile, notes)


def in_view(polygons, view: list[Segment]):
    box = merged_bounds(view)
    return [p for p in polygons if boxes_touch(box, (min(x for x, _ in p), max(x for x, _ in p),
                                                     min(y for _, y in p), max(y for _, y in p)))]


def side_view_of(segments: list[Segment], centre_lines: list[Line], polygons, layer: str) -> SideView | None:
    """The side view a centre line runs through, None when no centre line runs through a view;
    DxfError when only views along the axis are found or two side views compete."""
    candidates = centred_views(segments, centre_lines)
    if not candidates:
        return None
    found, refusals = [], []
    for axis, view in candidates:
        try:
            found.append(side_view(axis, view, in_view(polygons, view), f"layer {layer}"))
        except DxfError as refusal:
            refusals.append(refusal)
    if len(found) == 1:
        others = len(views(segments)) - 1
        extra = [f"layer {layer}: {others} other view(s) left out"] if others else []
        found[0].notes.extend(extra)
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
