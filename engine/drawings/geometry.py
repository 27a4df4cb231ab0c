"""The plane geometry of a drawing, shared by the DXF reader (engine.drawings) and the turning
models (engine.turning): points, lines and circular arcs in drawing units, from start to end."""
from __future__ import annotations

import math

import msgspec

Point = tuple[float, float]


class Line(msgspec.Struct, frozen=True):
    start: Point
    end: Point
    handle: str = ""

    def reversed(self) -> Line:
        return Line(self.end, self.start, self.handle)


class Arc(msgspec.Struct, frozen=True):
    """A circular arc from start to end about centre; ccw: counter-clockwise seen from +Z."""
    start: Point
    end: Point
    centre: Point
    ccw: bool
    handle: str = ""

    def reversed(self) -> Arc:
        return Arc(self.end, self.start, self.centre, not self.ccw, self.handle)

    @property
    def radius(self) -> float:
        return math.dist(self.start, self.centre)


Segment = Line | Arc
