"""engine.simulation.hobbing.contact_bounds for a batch, with numpy: the same bounds of a
collision's depth between the sampled heights and poses of a move's straight pieces, from the
exact distances (envelope_arrays) of every wanted pose at every height at once (envelope_arrays'
cheap bounds of a section's distance were tried in their place: near the blank, where a pose is
wanted, they are millimetres apart and settled nothing); a piece not settled is searched by
contact_bounds.deepest_on_piece (plain floats, so both paths report the same depth and height)."""
from __future__ import annotations

import math

import numpy as np

from .contact_bounds import LIMIT, deepest_on_piece, ends, open_pieces, x_reach
from .contact_records import COLLISION_TOLERANCE, Contact
from .envelope import HobBody
from .envelope_arrays import Sections
from .paths import AXES, pose_count
from .solids import Solid

# Every 4th height first (2 mm apart: the lines through exact samples bound a convex function
# through any samples, only less closely), all of them where that leaves a piece unsettled: a
# pose near the blank, 1 mm clear of it, is settled by a quarter of the sections (an approach)
STRIDES = (4, 1)


def exact_collision(solid: Solid, hob: HobBody, swivel: float, pieces: list, heights, radius) -> Contact | None:
    """contact_bounds.exact_collision (heights and radius: the solid's as arrays)."""
    pieces = open_pieces(solid, hob, swivel, pieces)
    if not pieces:
        return None
    best = (-math.inf, solid.z_high)
    for index in Poses(pieces, swivel).unsettled(solid, hob, swivel, heights, radius):
        best = max(best, deepest_on_piece(solid, hob, swivel, *ends(*pieces[index])))
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
        """The pieces whose bounds leave the hob possibly deeper than LIMIT (contact_bounds.piece_reaches)."""
        same = self.piece[:-1] == self.piece[1:]
        reach = x_reach(hob, swivel, solid)
        x_alone = _x_alone(self.cx[:-1], self.cx[1:], self.cz[:-1], self.cz[1:], reach)
        if not (same & (x_alone > LIMIT)).any():
            return []
        extent = hob.extent(swivel)
        side = np.where(self.cz + extent < solid.z_low, -1, np.where(self.cz - extent > solid.z_high, 1, 0))
        wanted = np.flatnonzero(_dilated(same & (x_alone > LIMIT), len(self.cx)) & (side == 0))
        if not wanted.size:
            return []
        base_upper = np.where(side == 0, _x_alone(self.cx, self.cx, self.cz, self.cz, reach), -np.inf)
        flags = same
        for stride in STRIDES:
            rows = Rows(self, wanted, solid, extent, heights, radius, stride)
            low, high = rows.pose_bounds(hob, swivel, self.cy[wanted])
            lower, upper = np.full(len(self.cx), -np.inf), base_upper.copy()
            lower[wanted], upper[wanted] = low, np.minimum(high, base_upper[wanted])
            flags = same & (_interval_bounds(lower, upper, x_alone, side, self.piece) > LIMIT)
            if not flags.any():
                return []
        return sorted(set(self.piece[:-1][flags].tolist()))


def _x_alone(x_one, x_two, z_one, z_two, reach):
    """contact_bounds.x_alone elementwise (hob centres' X and Z at the two ends)."""
    r0, largest, extent, band, c, z_low, z_high = reach
    near = np.where(x_one * x_two > 0.0, np.minimum(np.abs(x_one), np.abs(x_two)), 0.0)
    low = np.maximum(z_low - np.maximum(z_one, z_two), -extent)
    high = np.minimum(z_high - np.minimum(z_one, z_two), extent)
    gap = np.maximum(np.maximum(low - band, -band - high), 0.0)
    width = np.sqrt(np.maximum(r0 * r0 - (gap / c) ** 2, 0.0)) if c > 0.0 else r0
    return largest - (near - width)


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
    """The wanted poses' sections at every `stride`-th of the solid's heights within their reach,
    one row a pose (padded to the widest), and the reach (low, high) of each (the solid's faces,
    the hob's extent)."""

    def __init__(self, poses: Poses, wanted, solid: Solid, extent: float, heights, radius, stride: int) -> None:
        cz = poses.cz[wanted]
        first = np.searchsorted(heights, cz - extent)
        last = np.searchsorted(heights, cz + extent, side="right")
        width = max(int((last - first).max()), 1)
        raw = first[:, None] + np.arange(0, width, stride)[None, :]
        self.inside = raw < last[:, None]
        index = np.minimum(raw, len(heights) - 1)
        self.heights, self.radius = heights[index], radius[index]
        self.low = np.maximum(solid.z_low, cz - extent)
        self.high = np.minimum(solid.z_high, cz + extent)
        self.cx, self.cz = poses.cx[wanted][:, None], cz[:, None]

    def pose_bounds(self, hob: HobBody, swivel: float, cy):
        """(L, U) per pose (contact_bounds.pose_bound) from the exact distances."""
        distance = Sections(hob, swivel, self.cx, self.cz, self.heights).nearest(cy[:, None])
        valid = self.inside & np.isfinite(distance)
        depth = np.where(valid, self.radius - distance, -np.inf)
        return depth.max(axis=1), height_bounds(self.heights, valid, depth, depth, (self.low, self.high))


def height_bounds(h, valid, low, high, reach):
    """contact_bounds.height_bound per row (h, valid, low, high of shape (P, W), low and high
    −inf where not valid; a row's valid samples contiguous), inf for a row with none. Per
    sample j, the line through j and j − 1 carried up to j + 1, and through j and j + 1 carried
    down to j − 1; the stretch to the reach beyond the first (last) valid sample by the latter
    (former) carried that far."""
    rows, width = h.shape
    low_p, high_p, h_p = (np.empty((rows, width + 2)) for _ in range(3))
    for padded, values, edge in ((low_p, low, -np.inf), (high_p, high, -np.inf), (h_p, h, None)):
        padded[:, 1:-1] = values
        padded[:, 0], padded[:, -1] = (edge, edge) if edge is not None else (h[:, 0] - 1.0, h[:, -1] + 1.0)
    below, above = h - h_p[:, :-2], h_p[:, 2:] - h       # spacing to the sample below and above
    up = _line(high, low_p[:, :-2], above, below)
    down = _line(high, low_p[:, 2:], below, above)
    pair = valid[:, :-1] & valid[:, 1:]
    between = np.where(pair, np.minimum(up[:, :-1], down[:, 1:]), -np.inf).max(axis=1, initial=-np.inf)
    before = np.concatenate([np.zeros((rows, 1), bool), valid[:, :-1]], axis=1)
    after = np.concatenate([valid[:, 1:], np.zeros((rows, 1), bool)], axis=1)
    bottom, top = h - reach[0][:, None], reach[1][:, None] - h
    ends = np.maximum(
        np.where(valid & ~before & (bottom > 0.0), _line(high, low_p[:, 2:], bottom, above), -np.inf),
        np.where(valid & ~after & (top > 0.0), _line(high, low_p[:, :-2], top, below), -np.inf)).max(axis=1)
    bound = np.maximum(np.maximum(high.max(axis=1), between), ends)
    return np.where(valid.any(axis=1), bound, np.inf)


def _line(near, far, beyond, spacing):
    """contact_bounds._line elementwise."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.maximum(near, near + (near - far) * beyond / spacing)
