"""The slices of a cut (engine.simulation.hobbing.contact_arrays) that may be the least distance
at their height over a move's poses, found by cheap bounds before any nearest point is worked
out (issue 28). A cut needs per height of the unit the least distance of the hob's slices over
the poses (the reach it leaves) and the slices that come that near (the deepest below the
root, the first pose and lowest height of equal depths): any other slice may be left out, and
is:

* X alone bounds every slice from below: at dz from the centre the hob's points have
  |q| ≥ (|dz| − (L/2)·|sin A|)/cos A (mm, envelope's q), so none lies nearer the work axis
  than |cx| − √(R² − q²).
* The slices within SPREAD of their height's least such bound get envelope_arrays' bounds
  (tangent and X, and the distance of one point: an upper bound of the height's least).
* Every other slice must lie above that upper bound (by SLACK) in X alone, else the slices
  up to it get the bounds instead; of all those, the nearest points are worked out for the
  ones the bounds leave in.

Each step keeps every slice that may be the least, so the reach, the depths and the heights
are those of every slice worked out."""

from __future__ import annotations

import numpy as np

from .envelope import HobBody, sine_cosine
from .envelope_arrays import SLACK, Sections

SPREAD = 0.05   # mm: a level hob passing a height 0.25 mm off (half a pose step) comes about
                # 0.001 mm short of its least there; a swivelled one has a band of poses at R
FEW = 512       # slices (a radial infeed's few poses) all bounded at once: X alone is loose on its
                # slices far above and below the centre, and picking them out costs more than it saves


def least_sections(hob: HobBody, swivel: float, poses: tuple, heights, raw, last) -> tuple:
    """(index, radius, least) of a cut: the slices left, row-major (a pose's heights in order,
    poses in order), each one's height index and distance (inf where a bound rules it out), and
    the least distance per height (inf where no pose reaches it). poses: cx, cy, cz of shape
    (P, 1); raw (P, W): the index of each pose's heights, from its first on (rows padded to the
    widest), last: the index each pose's heights end before."""
    grid = Grid(raw, last, len(heights))
    if raw.size <= FEW:
        return least_of(Bounded(hob, swivel, poses, heights, grid, grid.valid))
    cx, cy, cz = poses
    floor = np.where(grid.valid, in_x(hob, swivel, cx, heights[grid.index] - cz), np.inf)
    near = grid.valid & (floor <= grid.least(floor)[grid.index] + SPREAD)
    found = Bounded(hob, swivel, poses, heights, grid, near)
    beyond = floor > found.ceiling[grid.index] + SLACK
    if not (near | beyond | ~grid.valid).all():      # a slice farther out may be the least: the bounds up to it
        found = Bounded(hob, swivel, poses, heights, grid, grid.valid & ~beyond)
    return least_of(found)


def least_of(found: Bounded) -> tuple:
    """least_sections' answer from the slices bounded."""
    return found.index, *found.nearest()


class Grid:
    """The poses' slices, a row a pose: raw (P, W) each one's height index from the pose's
    first (past the last height where the row is padded), valid where one of the pose's,
    index the height index clamped into the solid's."""

    def __init__(self, raw, last, count: int) -> None:
        self.raw, self.count = raw, count
        self.valid, self.index = raw < last[:, None], np.minimum(raw, count - 1)
        self.rows = np.arange(raw.shape[0])[:, None]
        self.shape = (raw.shape[0], count + raw.shape[1])

    def least(self, values):
        """The least of `values` (one per slice of the grid, inf where not valid) at each height
        (inf where none lands): each value gets a cell of its own in a table of a row a pose (its
        raw index: padding lands past the heights), the least of each column."""
        table = np.full(self.shape, np.inf)
        table[self.rows, self.raw] = values
        return table[:, :self.count].min(axis=0)


def least_at(values, index, count: int):
    """The least of `values` at each of `count` heights (index: each value's height), inf
    where none lands: for a few slices picked out of the grid (faster than its table)."""
    least = np.full(count, np.inf)
    np.minimum.at(least, index, values)
    return least


class Bounded:
    """The slices a mask marks with envelope_arrays' bounds: lower and upper per slice, and per
    height the least upper (the ceiling: no slice at that height that lies above it by SLACK
    is the least there)."""

    def __init__(self, hob: HobBody, swivel: float, poses: tuple, heights, grid: Grid, mask) -> None:
        rows, columns = np.nonzero(mask)
        self.index, self.count = grid.index[rows, columns], grid.count
        cx, self.cy, cz = (values[rows, 0] for values in poses)
        self.sections = Sections(hob, swivel, cx, cz, heights[self.index])
        self.lower, upper = self.sections.bounds(self.cy)
        self.ceiling = least_at(upper, self.index, self.count)

    def nearest(self) -> tuple:
        """(radius, least): the distance of each slice the bounds leave in (inf for the others),
        the least per height."""
        keep = self.lower <= self.ceiling[self.index] + SLACK
        radius = np.full(self.index.shape, np.inf)
        radius[keep] = found = self.sections.nearest(self.cy, keep)
        return radius, least_at(found, self.index[keep], self.count)


def in_x(hob: HobBody, swivel: float, cx, dz):
    """The least distance (mm) the hob's slice at dz from its centre may come to the work axis
    in X alone (module: |cx| − √(R² − q²) at the least |q| the end faces allow)."""
    s, c = sine_cosine(swivel)
    r = hob.radius
    q = np.maximum(np.abs(dz) - hob.half_length * abs(s), 0.0) / c
    return np.abs(cx) - np.sqrt(np.maximum(r * r - q * q, 0.0))
