"""The limits of a turning job's picture (engine.turning.plot): they frame the work, not the room
around it. The work is the part, the blank and every move of the passes except the travel at
the tool-change diameter (each operation comes down from the tool-change point and goes back up
to it, engine.turning.operations.from_and_to_tool_change). The tool-change point itself is framed
when it is near: when taking it in grows the frame by at most TOOL_CHANGE_GROWTH in each
direction, it shows where every operation starts. Far away (the default is 50 mm beyond the
drawing, engine.turning.defaults) it would shrink a small part into a corner; then the travel
lines leave the frame towards it and an arrow at the frame's edge gives its coordinates.

A small margin (MARGIN_FRACTION of each side, at least MIN_MARGIN_MM) keeps lines off the
frame's edge. The figure's size follows the frame's proportions at true shape."""
from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import msgspec

Point = tuple[float, float]   # (z, diameter)

TOOL_CHANGE_GROWTH = 1.5     # a frame up to 1.5 times as long or as tall still takes the point in
MARGIN_FRACTION = 0.04
MIN_MARGIN_MM = 0.5
# Diameter drawn at half the scale of Z: the upper half of the section keeps its true shape.
TRUE_SHAPE = 0.5
AXES_WIDTH_IN = 8.0
AXES_HEIGHT_IN = (1.5, 6.0)   # thinner parts are stretched up, taller ones drawn narrower …
MIN_AXES_WIDTH_IN = 4.0       # … down to this width, then stretched across
LEGEND_WIDTH_IN = 2.6         # beside the axes
TITLE_AND_LABELS_IN = 1.2     # above and below the axes
ARROW_OFFSET_PT = 45.0        # the tool-change note this far inside the frame from its arrow's tip
SAME_DIAMETER_MM = 1e-9


class Frame(msgspec.Struct, frozen=True):
    z_limits: tuple[float, float]
    x_limits: tuple[float, float]      # diameter
    aspect: float | str                # TRUE_SHAPE, or "auto" for a part too slender to see at it
    figure_size: tuple[float, float]   # inches

    def contains(self, point: Point) -> bool:
        (z0, z1), (x0, x1) = self.z_limits, self.x_limits
        return z0 <= point[0] <= z1 and x0 <= point[1] <= x1

    def clamped(self, point: Point) -> Point:
        """The point of the frame nearest to `point`."""
        (z0, z1), (x0, x1) = self.z_limits, self.x_limits
        return (min(max(point[0], z0), z1), min(max(point[1], x0), x1))

    def inward_offset(self, point: Point) -> Point:
        """Where (in points from clamped(point)) a note about `point` sits inside the frame."""
        z, x = point
        (z0, z1), (x0, x1) = self.z_limits, self.x_limits
        dz = -ARROW_OFFSET_PT if z > z1 else ARROW_OFFSET_PT if z < z0 else 0.0
        dx = -ARROW_OFFSET_PT / 2 if x > x1 else ARROW_OFFSET_PT / 2 if x < x0 else 0.0
        return (dz, dx)


def job_frame(part: Sequence[Point], stock, operations: Sequence[dict[str, list[Point]]],
              tool_change: Point | None) -> Frame:
    """The frame of the work (see the module's docstring); stock is (z_front, z_back, radius)."""
    work = bounds(work_points(part, stock, operations, tool_change))
    if tool_change is not None and is_near(tool_change, work):
        work = bounds([*corners(work), tool_change])
    return framed(work)


def work_points(part, stock, operations, tool_change: Point | None) -> list[Point]:
    points = list(part) + [(0.0, 0.0)]   # the axis is always in the picture
    if stock is not None:
        z_front, z_back, radius = stock
        points += [(z_front, 2.0 * radius), (z_back, 2.0 * radius)]
    for lines in operations:
        points += [p for line in lines.values() for p in line
                   if not math.isnan(p[0]) and not at_tool_change(p, tool_change)]
    return points


def at_tool_change(point: Point, tool_change: Point | None) -> bool:
    return tool_change is not None and abs(point[1] - tool_change[1]) <= SAME_DIAMETER_MM


Bounds = tuple[float, float, float, float]   # z_min, z_max, x_min, x_max


def bounds(points: Iterable[Point]) -> Bounds:
    zs, xs = zip(*points)
    return (min(zs), max(zs), min(xs), max(xs))


def corners(box: Bounds) -> list[Point]:
    return [(box[0], box[2]), (box[1], box[3])]


def is_near(point: Point, work: Bounds) -> bool:
    grown = bounds([*corners(work), point])
    return (span(grown, 0) <= TOOL_CHANGE_GROWTH * span(work, 0)
            and span(grown, 2) <= TOOL_CHANGE_GROWTH * span(work, 2))


def span(box: Bounds, first: int) -> float:
    return box[first + 1] - box[first]


def framed(work: Bounds) -> Frame:
    """The work with its margins and a figure of its shape."""
    z_margin = max(MARGIN_FRACTION * span(work, 0), MIN_MARGIN_MM)
    x_margin = max(MARGIN_FRACTION * span(work, 2), MIN_MARGIN_MM / TRUE_SHAPE)   # on the diameter
    z_limits = (work[0] - z_margin, work[1] + z_margin)
    x_limits = (work[2] - x_margin, work[3] + x_margin)
    width, height, aspect = axes_size(z_limits[1] - z_limits[0], (x_limits[1] - x_limits[0]) * TRUE_SHAPE)
    return Frame(z_limits, x_limits, aspect, (width + LEGEND_WIDTH_IN, height + TITLE_AND_LABELS_IN))


def axes_size(length: float, height_mm: float) -> tuple[float, float, float | str]:
    """(width, height) in inches of the axes showing length × height mm, and their aspect: true
    shape where it fits in AXES_WIDTH_IN × AXES_HEIGHT_IN's most; a part too slender (a long
    shaft) or too short (a wide disc) for that is stretched across its short side instead."""
    low, high = AXES_HEIGHT_IN
    height = AXES_WIDTH_IN * height_mm / length
    if height < low:
        return AXES_WIDTH_IN, low, "auto"
    if height <= high:
        return AXES_WIDTH_IN, height, TRUE_SHAPE
    width = high * length / height_mm
    return (width, high, TRUE_SHAPE) if width >= MIN_AXES_WIDTH_IN else (MIN_AXES_WIDTH_IN, high, "auto")
