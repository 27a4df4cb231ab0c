"""Profile and tool-path segments as job parameters: JSON lists a DBA can read and edit.

    ["line", z0, r0, z1, r1]
    ["arc",  z0, r0, z1, r1, zc, rc, ccw]

mm, machine coordinates: z along the axis, r the radius (a program's X is the diameter);
ccw: counter-clockwise seen with Z to the right and the radius up (G03 on a lathe).
"""
from __future__ import annotations

import math
from typing import NoReturn

from ..drawings.geometry import Arc, Line, Segment
from ..drawings.profile import END_MATCH_TOLERANCE_MM
from ..errors import EngineError

DIGITS = 6             # mm to 1 nm: far below any drawing's accuracy, short in SQL
ARC_RADIUS_TOLERANCE = 0.01   # mm: an arc's two ends must be this close to one radius


def segment_param(segment: Segment) -> list:
    (z0, r0), (z1, r1) = segment.start, segment.end
    ends = [round(value, DIGITS) for value in (z0, r0, z1, r1)]
    if isinstance(segment, Line):
        return ["line", *ends]
    zc, rc = segment.centre
    return ["arc", *ends, round(zc, DIGITS), round(rc, DIGITS), bool(segment.ccw)]


def path_param(segments: list[Segment]) -> list[list]:
    return [segment_param(segment) for segment in segments]


def path_from_param(items, where: str) -> list[Segment]:
    """Segments from their JSON form; `where` names the parameter in an error."""
    if not isinstance(items, list):
        raise EngineError(f"{where} must be a list of segments, not {type(items).__name__}; "
                          f"fix it in SQL (job.params / job.module_params)")
    segments: list[Segment] = []
    for index, item in enumerate(items):
        segment = _segment(item)
        if segment is None:
            _refuse(item, f"{where}[{index}]")
        if segments:
            _require_continuity(segments[-1], segment, f"{where}[{index}]")
        segments.append(segment)
    return segments


def _require_continuity(previous: Segment, segment: Segment, where: str) -> None:
    """A profile and a drawn path are chains: each segment starts where the one before ends
    (as the drawing's reader joined them)."""
    gap = math.dist(previous.end, segment.start)
    if gap > END_MATCH_TOLERANCE_MM:
        raise EngineError(f"{where} starts at (z {segment.start[0]:g}, r {segment.start[1]:g}), {gap:.4g} mm from "
                          f"where the segment before ends (z {previous.end[0]:g}, r {previous.end[1]:g}); consecutive "
                          f"segments must meet within {END_MATCH_TOLERANCE_MM:g} mm: fix it in SQL")


def _segment(item) -> Segment | None:
    """The segment, or None when the item is not one (the caller names it)."""
    if type(item) is not list or not item:
        return None
    kind, numbers = item[0], item[1:]
    if kind == "line" and len(numbers) == 4 and _numbers(numbers):
        return Line((numbers[0], numbers[1]), (numbers[2], numbers[3]))
    if kind == "arc" and len(numbers) == 7 and _numbers(numbers[:6]):
        start, end, centre = (numbers[0], numbers[1]), (numbers[2], numbers[3]), (numbers[4], numbers[5])
        if abs(math.dist(start, centre) - math.dist(end, centre)) <= ARC_RADIUS_TOLERANCE:
            return Arc(start, end, centre, bool(numbers[6]))
    return None


def _refuse(item, where: str) -> NoReturn:
    shape = '["line", z0, r0, z1, r1] or ["arc", z0, r0, z1, r1, zc, rc, ccw]'
    if type(item) is not list or not item or item[0] not in ("line", "arc"):
        raise EngineError(f"{where} = {item!r} is not a segment; write {shape}")
    kind = item[0]
    if len(item) != (5 if kind == "line" else 8) or not _numbers(item[1:7]):
        raise EngineError(f"{where} = {item!r}: a {kind} is {shape.split(' or ')[kind == 'arc']}")
    raise EngineError(f"{where} = {item!r}: start and end are not on one circle about the centre "
                      f"(radii differ by more than {ARC_RADIUS_TOLERANCE} mm)")


def _numbers(values) -> bool:
    for value in values:
        if type(value) not in (int, float) or not math.isfinite(value):
            return False
    return True
