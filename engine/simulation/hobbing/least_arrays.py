"""The slices of a cut (engine.simulation.hobbing.contact_arrays) that may be the least distance
at their height over a move's poses, found by cheap bounds before any nearest point is worked
out (issue 28). A cut needs per height of the unit the least distance of the hob's slices over
the poses (the reach it leaves) and the slices that come that near (the deepest below the
root, the first pose and lowest height of equal depths): any other slice may be left out, and
is, in three rounds, each on fewer slices:

* An upper bound of the least per height: the distance of one point of a few slices, those
  of each pose at the two heights around its closest approach to the work axis (the hob axis'
  point nearest it, t = −cy/cos A along the axis, clamped between the end faces: the hob's
  point nearest the work axis lies in that slice), and every slice of the pose nearest in X
  (a radial infeed's poses share their heights).
* X alone, for every slice: at dz from the centre the hob's points have |q| ≥ (|dz| −
  (L/2)·|sin A|)/cos A (mm, envelope's q), so none lies nearer the axis than |cx| − √(R² − q²).
  A slice that far above the upper bound (by SLACK) is not the least at its height.
* envelope_arrays' bounds (tangent and X) on the slices left, the nearest points of those they
  leave in. Each round keeps every slice that may be the least, so the reach, the depths and
  the heights are those of every slice worked out."""
from __future__ import annotations

import numpy as np

from .envelope import HobBody, sine_cosine
from .envelope_arrays import SLACK, Sections


def least_sections(hob: HobBody, swivel: float, poses: tuple, heights, index, valid, span: tuple) -> tuple:
    """(index, radius, least) of a cut: the slices left, row-major (a pose's heights in order,
    poses in order), each one's height index and distance (inf where a bound rules it out), and
    the least distance per height (inf where no pose reaches it). poses: cx, cy, cz of shape
    (P, 1); index (P, W): the height index of each pose's slices, valid where it is one of
    the pose's (rows padded to the widest), span = (first, last) the indices each pose reaches
    (last excluded)."""
    cx, cy, cz = poses
    count = len(heights)
    ceiling = upper_per_height(hob, swivel, poses, heights, span) + SLACK
    rows, columns = np.nonzero(valid & (in_x(hob, swivel, cx, heights[index] - cz) <= ceiling[index]))
    index, cx, cy, cz = index[rows, columns], cx[rows, 0], cy[rows, 0], cz[rows, 0]
    sections = Sections(hob, swivel, cx, cz, heights[index])
    lower, upper = sections.bounds(cy)
    keep = lower <= least_at(upper, index, count)[index] + SLACK
    radius = np.full(index.shape, np.inf)
    radius[keep] = sections.nearest(cy, keep)
    return index, radius, least_at(radius, index, count)


def upper_per_height(hob: HobBody, swivel: float, poses: tuple, heights, span: tuple):
    """Per height, an upper bound (mm) of the least distance over the poses (inf where none of
    the slices tried has a point): the module's few slices, each one's distance of one point."""
    cx, cy, cz = poses
    first, last = span
    s, c = sine_cosine(swivel)
    along = np.minimum(np.maximum(-cy[:, 0] / c, -hob.half_length), hob.half_length)   # mm along the hob axis
    closest, end = np.searchsorted(heights, cz[:, 0] + along * s), last - 1
    inner, poses = int(np.argmin(np.abs(cx[:, 0]))), np.arange(len(first))
    rows = np.concatenate([poses, poses, np.full(last[inner] - first[inner], inner)])
    at = np.concatenate([np.minimum(np.maximum(closest - 1, first), end), np.minimum(np.maximum(closest, first), end),
                         np.arange(first[inner], last[inner])])
    upper = Sections(hob, swivel, cx[rows, 0], cz[rows, 0], heights[at]).upper(cy[rows, 0])
    return least_at(upper, at, len(heights))


def in_x(hob: HobBody, swivel: float, cx, dz):
    """The least distance (mm) the hob's slice at dz from its centre may come to the work axis
    in X alone (module: |cx| − √(R² − q²) at the least |q| the end faces allow)."""
    s, c = sine_cosine(swivel)
    r = hob.radius
    q = np.maximum(np.abs(dz) - hob.half_length * abs(s), 0.0) / c
    return np.abs(cx) - np.sqrt(np.maximum(r * r - q * q, 0.0))


def least_at(values, index, count: int):
    """The least of `values` at each of `count` heights (index: each value's height), inf
    where none lands."""
    least = np.full(count, np.inf)
    np.minimum.at(least, index, values)
    return least
