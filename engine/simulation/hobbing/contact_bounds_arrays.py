"""engine.simulation.hobbing.contact_bounds for a batch, with numpy: the same bounds of a
collision's depth between the sampled heights and poses of a move's straight pieces, every
pose and height at once, first from envelope_arrays' cheap bounds of each section's distance
(a lower and an upper bound stand in for the value: the far sample's lower bound of the depth,
the near one's upper bound), then, where those reach the tolerance, from the exact distances;
a piece still not settled is searched by contact_bounds.deepest_on_piece (plain floats, so
both paths report the same depth and height)."""
from __future__ import annotations

import math

import numpy as np

from .contact_bounds import LIMIT, deepest_on_piece
from .contact_records import COLLISION_TOLERANCE, Contact
from .envelope import HobBody
from .envelope_arrays import Sections
from .paths import AXES, pose_count
from .solids import Solid


def exact_collision(solid: Solid, hob: HobBody, swivel: float, pieces: list, heights, radius) -> Contact | None:
    """contact_bounds.exact_collision (heights and radius: the solid's as arrays)."""
    moves = Poses(pieces, swivel)
    flagged = moves.unsettled(solid, hob, swivel, heights, radius)
    best = (-math.inf, solid.z_high)
    for index in flagged:
        a, b = pieces[index]
        start, end = (tuple(point.get(axis, 0.0) for axis in AXES) for point in (a, b))
        best = max(best, deepest_on_piece(solid, hob, swivel, start, end))
    return Contact(solid, best[0], best[1], False) if best[0] > COLLISION_TOLERANCE else None


class Poses:
    """The hob centres (DIN, mm) along a move's pieces, evenly spaced on each (paths.pose_count),
    with each pose's piece."""

    def __init__(self, pieces: list, swivel: float) -> None:
        counts = [pose_count(a, b) for a, b in pieces]
        share = np.concatenate([np.arange(count) / (count - 1) for count in counts])
        self.piece = np.repeat(np.arange(len(pieces)), counts)
        x, y, z = (np.concatenate([np.full(count, a.get(axis, 0.0)) for (a, _), count in zip(pieces, counts)]) +
                   share * np.concatenate([np.full(count, b.get(axis, 0.0) - a.get(axis, 0.0))
                                           for (a, b), count in zip(pieces, counts)]) for axis in AXES)
        angle = math.radians(swivel)
        self.cx, self.cy, self.cz = x, y * math.cos(angle), z + y * math.sin(angle)

    def unsettled(self, solid: Solid, hob: HobBody, swivel: float, heights, radius) -> list[int]:
        """The pieces whose bounds (cheap, then exact) leave the hob possibly deeper than LIMIT."""
        same = self.piece[:-1] == self.piece[1:]
        x_alone = _x_alone(self.cx, hob.radius, solid.largest_radius)
        if not (same & (x_alone > LIMIT)).any():
            return []
        extent = hob.extent(swivel)
        side = np.where(self.cz + extent < solid.z_low, -1, np.where(self.cz - extent > solid.z_high, 1, 0))
        wanted = np.flatnonzero(_dilated(same & (x_alone > LIMIT), len(self.cx)) & (side == 0))
        if not wanted.size:
            return []
        rows = Rows(self, wanted, solid, extent, heights, radius)
        base_upper = np.where(side == 0, solid.largest_radius - (np.abs(self.cx) - hob.radius), -np.inf)
        flags = None
        for exact in (False, True):
            low, high = rows.pose_bounds(hob, swivel, self.cy[wanted], exact)
            lower, upper = np.full(len(self.cx), -np.inf), base_upper.copy()
            lower[wanted], upper[wanted] = low, np.minimum(high, base_upper[wanted])
            flags = same & (_interval_bounds(lower, upper, x_alone, side, self.piece) > LIMIT)
            if not flags.any():
                return []
        return sorted(set(self.piece[:-1][flags].tolist()))


def _x_alone(x, r0: float, largest: float):
    """contact_bounds.x_alone_bounds between consecutive poses."""
    near = np.where(x[:-1] * x[1:] > 0.0, np.minimum(np.abs(x[:-1]), np.abs(x[1:])), 0.0)
    return largest - (near - r0)


def _dilated(active, count: int):
    """The poses i − 1 … i + 2 of each active interval i (between poses i and i + 1)."""
    wanted = np.zeros(count + 3, bool)
    for shift in range(4):
        wanted[shift:shift + len(active)] |= active
    return wanted[1:count + 1]


def _interval_bounds(lower, upper, x_alone, side, piece):
    """contact_bounds.interval_bounds for every interval at once (across pieces too: the caller
    keeps those within one piece); a line only from poses of the interval's own piece."""
    count = len(lower)
    pad_low = np.concatenate([[-np.inf], lower, [-np.inf, -np.inf]])
    pad_piece = np.concatenate([[-1], piece, [-1, -1]])
    near_left, far_left = upper[:-1], pad_low[:count - 1]
    near_right, far_right = upper[1:], pad_low[3:count + 2]
    left = np.where(pad_piece[:count - 1] == piece[:-1], _pose_line(near_left, far_left), np.inf)
    right = np.where(pad_piece[3:count + 2] == piece[1:], _pose_line(near_right, far_right), np.inf)
    bounds = np.minimum(x_alone, np.minimum(left, right))
    return np.where((side[:-1] == side[1:]) & (side[:-1] != 0), -np.inf, bounds)


def _pose_line(near, far):
    """contact_bounds._pose_line elementwise."""
    usable = np.isfinite(near) & (far != -np.inf)
    with np.errstate(invalid="ignore"):
        return np.where(usable, np.maximum(near, 2.0 * near - far), np.inf)


class Rows:
    """The wanted poses' sections at the solid's heights within their reach, one row a pose
    (padded to the widest), and the reach (low, high) of each (the solid's faces, the hob's
    extent)."""

    def __init__(self, poses: Poses, wanted, solid: Solid, extent: float, heights, radius) -> None:
        cz = poses.cz[wanted]
        first = np.searchsorted(heights, cz - extent)
        last = np.searchsorted(heights, cz + extent, side="right")
        width = max(int((last - first).max()), 1)
        raw = first[:, None] + np.arange(width)[None, :]
        self.inside = raw < last[:, None]
        index = np.minimum(raw, len(heights) - 1)
        self.heights, self.radius = heights[index], radius[index]
        self.low = np.maximum(solid.z_low, cz - extent)
        self.high = np.minimum(solid.z_high, cz + extent)
        self.cx, self.cz = poses.cx[wanted][:, None], cz[:, None]

    def pose_bounds(self, hob: HobBody, swivel: float, cy, exact: bool):
        """(L, U) per pose (contact_bounds.pose_bound), from envelope_arrays' bounds of each
        section's distance or, with `exact`, from the distances themselves."""
        sections = Sections(hob, swivel, self.cx, self.cz, self.heights)
        if exact:
            lower = upper = sections.nearest(cy[:, None])
        else:
            lower, upper = sections.bounds(cy[:, None])
        valid = self.inside & ~sections.empty & np.isfinite(upper) & np.isfinite(lower)
        low = np.where(valid, self.radius - upper, -np.inf)
        high = np.where(valid, self.radius - lower, -np.inf)
        return low.max(axis=1), height_bounds(self.heights, valid, low, high, (self.low, self.high))


def height_bounds(h, valid, low, high, reach):
    """contact_bounds.height_bound per row (h, valid, low, high of shape (P, W); a row's valid
    samples contiguous), inf for a row with none."""
    rows, width = h.shape
    pad = np.full((rows, 1), -np.inf)
    low_p, high_p = np.hstack([pad, low, pad, pad]), np.hstack([pad, high, pad, pad])
    h_p = np.hstack([h[:, :1] - 1.0, h, h[:, -1:] + 1.0, h[:, -1:] + 2.0])
    valid_p = np.hstack([np.zeros((rows, 1), bool), valid, np.zeros((rows, 2), bool)])
    j = np.arange(1, width + 1)          # the padded columns of the samples
    step = h_p[:, j + 1] - h_p[:, j]
    left = np.where(valid_p[:, j - 1], _line(high_p[:, j], low_p[:, j - 1], step, h_p[:, j] - h_p[:, j - 1]), np.inf)
    right = np.where(valid_p[:, j + 2], _line(high_p[:, j + 1], low_p[:, j + 2], step,
                                              h_p[:, j + 2] - h_p[:, j + 1]), np.inf)
    between = np.where(valid_p[:, j] & valid_p[:, j + 1], np.minimum(left, right), -np.inf).max(axis=1)
    ends = np.maximum(_end(h, valid, low, high, reach[0], 1), _end(h, valid, low, high, reach[1], -1))
    return np.maximum(np.maximum(high.max(axis=1), between), ends)


def _end(h, valid, low, high, reach, sense: int):
    """The bound over the stretch from a row's first (sense 1) or last (−1) valid sample to the
    reach beyond it: the line through it and its inner neighbour; inf without one."""
    rows, width = h.shape
    order = np.arange(width) if sense == 1 else np.arange(width)[::-1]
    at = order[np.argmax(valid[:, order], axis=1)]
    inner = np.clip(at + sense, 0, width - 1)
    row = np.arange(rows)
    beyond = (h[row, at] - reach) * sense
    has_inner = valid[row, inner] & (inner != at)
    with np.errstate(invalid="ignore", divide="ignore"):
        line = _line(high[row, at], low[row, inner], np.maximum(beyond, 0.0), (h[row, inner] - h[row, at]) * sense)
    found = np.where(has_inner, line, np.inf)
    return np.where(valid.any(axis=1), np.where(beyond > 0.0, found, -np.inf), np.inf)


def _line(near, far, beyond, spacing):
    """contact_bounds._line elementwise."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.maximum(near, near + (near - far) * beyond / spacing)
