"""The plane geometry of a drawing, shared by the DXF reader (engine.drawings) and the turning
models (engine.turning): points, lines and circular arcs in drawing units, from start to end."""
from __future__ import annotations

import math
from dataclasses import dataclass

Point = tuple[float, float]


@dataclass(frozen=True, slots=True)
class Line:
    start: Point
    end: Point
    handle: str = ""

    def reversed(self) -> Line:
        return Line(self.end, self.start, self.handle)


@dataclass(frozen=True, slots=True)
class Arc:
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
