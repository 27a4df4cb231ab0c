"""Where a blended move may run off its programmed path (LinuxCNC `G64 P<t>`, the tolerance each
plain line carries: engine.verifier.expansion.PlainLine.blend, mm; docs/reference/
linuxcnc-lathe.md §3).

LinuxCNC keeps the path within t of the programmed one (g-code.adoc G64). It leaves a move's line
in two ways only: at the junction of two moves, where the planner rounds the corner by a curve
tangent to both (an arc inside the triangle of the corner and its two tangent points, or a
parabolic blend: the sum of the two motions, inside the parallelogram they span), and by its naive
CAM detector, which merges consecutive near-collinear feed moves (G64 Q, P when not given) into
one line within t of them. Rapids are never merged. So:

* a feed move (cut) may be anywhere within t of its line (`tube`);
* at a junction, the tool may run anywhere inside the angle the two moves make, within t of
  them (`corner`): the parallelogram the way back along the first move's last piece and the way on
  along the second's first piece span from the corner (it holds both kinds of blend), cut to the
  tube. Two moves in line (on, or straight back) make no corner. Next to a rapid, the part of it
  within t of the rapid is run at rapid, and must be air (the part next to a cut is the cut's,
  checked with the cut's tube against the part).
"""
from __future__ import annotations

import math

from shapely.geometry import LineString, Polygon
from shapely.geometry.base import BaseGeometry
from shapely.ops import unary_union

from .follow import Move
from .work import Point


def tube(move: Move, line: BaseGeometry) -> BaseGeometry:
    """Everywhere within the move's blend tolerance of its line."""
    return line.buffer(move.blend) if move.blend > 0 else line


def corner(before: Move | None, after: Move, kind: str | None = None) -> BaseGeometry | None:
    """The region the blend at the junction of `before` and `after` may sweep, or None: no blend
    (G61, the first move, or two moves in line). With `kind`, only its part within the tolerance
    of the move(s) of that kind: where the tool still runs as that move does."""
    blend = max(after.blend, before.blend if before is not None else 0.0)
    if before is None or blend <= 0:
        return None
    joint = after.points[0]
    back, on = _neighbour(reversed(before.points), joint), _neighbour(after.points, joint)
    if back is None or on is None:
        return None
    far = (back[0] + on[0] - joint[0], back[1] + on[1] - joint[1])
    span = Polygon([joint, back, far, on])
    if span.area <= 1e-12:
        return None
    pieces = [piece for piece, move in (([back, joint], before), ([joint, on], after)) if kind in (None, move.kind)]
    return span.intersection(unary_union([LineString(piece) for piece in pieces]).buffer(blend))


def _neighbour(points, joint: Point) -> Point | None:
    """The first of `points` away from the junction: the other end of the move's piece at it."""
    return next((point for point in points if math.dist(point, joint) > 1e-9), None)
