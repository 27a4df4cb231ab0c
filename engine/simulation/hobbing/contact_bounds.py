"""Rigorous collision depths between the sampled heights and poses (issue 28), in plain floats.

The hob is convex. For one pose, d(h), the least distance from the work axis of its slice at
height h (mm), is convex in h; along a straight piece of a move (X, Y, Z moving together, the
swivel constant) the hob only translates, and F(s, h) over the piece's share s and the height
is jointly convex (a partial minimum of a convex function over a convex set). A solid of
revolution's radius R(h) is linear (a cylinder or a cone), so the depth D = R − F is concave,
and so is M(s), the deepest over the heights at one pose. A concave function lies below the
line through two of its values outside their chord, so between exact samples:

* In height, on [h_j, h_j+1] D ≤ the line through samples j−1, j extended right, and ≤ the one
  through j+2, j+1 extended left (one line at either end of the hob's reach; none: unbounded).
* In s, the same per pose, with bounds in place of values: the line through the far pose's
  lower bound L (its deepest sample) and the near pose's upper bound U (the height bound) stays
  above M beyond the near pose ((U − M)(1 + t) + (M_far − L)·t ≥ 0 for t ≥ 0 steps past it).
  X alone bounds M too, on a whole interval (x_alone: the hob's width along X at the heights
  it meets the solid at), and settles most poses and pieces before any section is worked out.

Where a bound reaches COLLISION_TOLERANCE less SLACK, `deepest_on_piece` finds the true deepest
point of the piece: golden sections over s, each point's deepest height by golden sections
over h, brackets narrowed below REFINE_BRACKET (mm). engine.simulation.hobbing.contact and
contact_arrays both call it, so both paths report the same depth and height."""
from __future__ import annotations

import math
from bisect import bisect_left, bisect_right

from .contact_records import COLLISION_TOLERANCE, Contact
from .envelope import HobBody, centres, nearest_radii, nearest_radius, sine_cosine
from .paths import AXES, pieces_poses
from .solids import Solid

REFINE_BRACKET = 1e-5     # mm: the golden sections stop below this, in height and along the piece
SLACK = 1e-6              # mm a bound must stay under the tolerance by (distances are exact to ~1e-9 mm)
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
LIMIT = COLLISION_TOLERANCE - SLACK


def pose_bound(heights: list[float], radius: list[float], first: int, lower: list[float], upper: list[float],
               reach: tuple[float, float]) -> tuple[float, float]:
    """(L, U) for one pose (mm): its deepest sample and a bound of its deepest point over the
    heights reach = (low, high) (the solid's faces and the hob's extent). `lower`/`upper`
    bound the distance at heights[first], heights[first + 1], …; inf where the hob has no point
    (at its extremity, by rounding: left out, the end interval covers it)."""
    valid = [j for j, value in enumerate(lower) if value != math.inf]
    if not valid:
        return -math.inf, math.inf
    begin, end = first + valid[0], first + valid[-1] + 1
    low = [radius[first + j] - upper[j] for j in range(valid[0], valid[-1] + 1)]
    high = [radius[first + j] - lower[j] for j in range(valid[0], valid[-1] + 1)]
    return max(low), height_bound(heights[begin:end], low, high, reach)


def height_bound(h: list[float], low: list[float], high: list[float], reach: tuple[float, float]) -> float:
    """The deepest D can be over reach, from samples at heights h (ascending) with low ≤ D ≤ high
    there: the module's lines, the far sample's lower bound and the near one's upper bound."""
    count = len(h)
    bound = max(high)
    if reach[0] < h[0]:
        bound = max(bound, _line(high[0], low[1], h[0] - reach[0], h[1] - h[0]) if count > 1 else math.inf)
    if reach[1] > h[-1]:
        bound = max(bound, _line(high[-1], low[-2], reach[1] - h[-1], h[-1] - h[-2]) if count > 1 else math.inf)
    for j in range(count - 1):
        step = h[j + 1] - h[j]
        left = _line(high[j], low[j - 1], step, h[j] - h[j - 1]) if j > 0 else math.inf
        right = _line(high[j + 1], low[j + 2], step, h[j + 2] - h[j + 1]) if j + 2 < count else math.inf
        bound = max(bound, min(left, right))
    return bound


def _line(near: float, far: float, beyond: float, spacing: float) -> float:
    """The most the line through (far, one spacing back) and (near) reaches up to `beyond` past
    the near sample (mm): its value at one end of that stretch."""
    return max(near, near + (near - far) * beyond / spacing)


def interval_bounds(poses: list[tuple[float, float]], x_alone: list[float], overlap: list[int]) -> list[float]:
    """Per interval between consecutive poses of one piece, a bound of the deepest point (mm).
    poses: (L, U) per pose (U inf: unbounded, L −inf: no sample); x_alone: the X-alone bound
    on each interval; overlap: per pose −1/0/1 for the hob below/within/above the solid's
    heights (both ends out on one side: the interval never reaches them)."""
    bounds = []
    count = len(poses)
    for i in range(count - 1):
        if overlap[i] == overlap[i + 1] != 0:
            bounds.append(-math.inf)
            continue
        left = _pose_line(poses[i][1], poses[i - 1][0]) if i > 0 else math.inf
        right = _pose_line(poses[i + 1][1], poses[i + 2][0]) if i + 2 < count else math.inf
        bounds.append(min(x_alone[i], left, right))
    return bounds


def _pose_line(near: float, far: float) -> float:
    """_line over one pose step, with an unbounded near pose or a far pose without a sample
    giving no bound (inf)."""
    if near == math.inf or far == -math.inf or near == -math.inf:
        return math.inf
    return _line(near, far, 1.0, 1.0)


def x_reach(hob: HobBody, swivel: float, solid: Solid) -> tuple:
    """What x_alone needs of the hob and the solid: r0, the solid's largest radius, the hob's
    extent along Z, the half-height band (L/2)·|sin A| of its X-most generator, cos A, and the
    solid's faces (mm)."""
    s, c = sine_cosine(swivel)
    return hob.radius, solid.largest_radius, hob.extent(swivel), hob.half_length * abs(s), c, solid.z_low, solid.z_high


def x_alone(one: tuple, two: tuple, reach: tuple) -> float:
    """A bound of the depth (mm) at every pose between the hob centres `one` and `two` (DIN, mm)
    from X alone. At height dz from the centre the hob's points lie at most w(dz) from it along
    X: its points there have q = (t·sin A − dz)/cos A for some t within ±L/2, so
    w = √(r0² − q²) with |q| at least the distance of dz from the band ±(L/2)|sin A|, over
    cos A. Over the heights both poses meet the solid at, the widest w; every point lies at
    least |x| − w from the work axis, |x| linear between the poses (0 if x changes sign)."""
    r0, largest, extent, band, c, z_low, z_high = reach
    near = min(abs(one[0]), abs(two[0])) if one[0] * two[0] > 0.0 else 0.0
    low = max(z_low - max(one[2], two[2]), -extent)
    high = min(z_high - min(one[2], two[2]), extent)
    gap = max(0.0, low - band, -band - high)
    width = math.sqrt(max(r0 * r0 - (gap / c) ** 2, 0.0)) if c > 0.0 else r0
    return largest - (near - width)


def deepest_on_piece(solid: Solid, hob: HobBody, swivel: float, start: tuple[float, float, float],
                     end: tuple[float, float, float]) -> tuple[float, float]:
    """The deepest the hob comes into the solid on the straight piece start → end (machine X, Y,
    Z, mm) and at which height: golden sections over the share s of the piece (where the hob's
    heights meet the solid's), each s's deepest height by golden sections (M(s) is concave)."""
    a, b = centres(*start, swivel), centres(*end, swivel)
    extent = hob.extent(swivel)
    span = _overlap(a[2], b[2], solid.z_low - extent, solid.z_high + extent)
    if span is None:
        return -math.inf, solid.z_high
    length = math.dist(start, end)
    tolerance = REFINE_BRACKET / length if length > 0.0 else 1.0

    def at(s: float) -> tuple[float, float]:
        cx, cy, cz = (p + s * (q - p) for p, q in zip(a, b))
        return deepest_at(solid, hob, swivel, (cx, cy, cz), extent)

    return _golden(at, span[0], span[1], tolerance)


def deepest_at(solid: Solid, hob: HobBody, swivel: float, centre: tuple, extent: float) -> tuple[float, float]:
    """(the deepest depth, its height) of one pose (hob centre, DIN, mm) in the solid."""
    cx, cy, cz = centre
    low, high = max(solid.z_low, cz - extent), min(solid.z_high, cz + extent)
    if low > high:
        return -math.inf, solid.z_high

    def depth(h: float) -> tuple[float, float]:
        return solid.radius_at(h) - nearest_radius(hob, swivel, cx, cy, cz, h), h

    return _golden(depth, low, high, REFINE_BRACKET)


def _golden(f, low: float, high: float, tolerance: float) -> tuple[float, float]:
    """The greatest of f(x)[0] for a concave f on [low, high] (f returns (value, what to
    report)): golden sections until the bracket is below `tolerance`, the ends tried too (the
    deepest may lie on a face); the best of every point tried (each is a true value)."""
    best = max(f(low), f(high))
    if high - low <= tolerance:
        return best
    one, two = high - GOLDEN * (high - low), low + GOLDEN * (high - low)
    f_one, f_two = f(one), f(two)
    while high - low > tolerance:
        if f_one[0] >= f_two[0]:
            high, two, f_two = two, one, f_one
            one = high - GOLDEN * (high - low)
            f_one = f(one)
        else:
            low, one, f_one = one, two, f_two
            two = low + GOLDEN * (high - low)
            f_two = f(two)
    return max(best, f_one, f_two)


def _overlap(z_start: float, z_end: float, low: float, high: float) -> tuple[float, float] | None:
    """The shares s of [0, 1] where z_start + s·(z_end − z_start) lies in [low, high] (mm)."""
    move = z_end - z_start
    if move == 0.0:
        return (0.0, 1.0) if low <= z_start <= high else None
    one, two = (low - z_start) / move, (high - z_start) / move
    first, last = max(0.0, min(one, two)), min(1.0, max(one, two))
    return (first, last) if first <= last else None


def overlap_side(cz: float, extent: float, solid: Solid) -> int:
    """−1 where the hob centred at height cz lies wholly below the solid, 1 above, else 0."""
    if cz + extent < solid.z_low:
        return -1
    return 1 if cz - extent > solid.z_high else 0


def exact_collision(solid: Solid, hob: HobBody, swivel: float, pieces: list, counted: list[int]) -> Contact | None:
    """The hob's deepest point in the solid over the move's straight pieces (machine positions),
    where deeper than COLLISION_TOLERANCE: each piece a bound settles is passed over, the rest
    searched exactly (deepest_on_piece). counted[0] grows by the sections worked out."""
    best = (-math.inf, solid.z_high)
    for a, b in open_pieces(solid, hob, swivel, pieces):
        xs, ys, zs = pieces_poses([(a, b)])
        poses = [centres(x, y, z, swivel) for x, y, z in zip(xs, ys, zs)]
        if piece_reaches(solid, hob, swivel, poses, counted):
            best = max(best, deepest_on_piece(solid, hob, swivel, *ends(a, b)))
    return Contact(solid, best[0], best[1], False) if best[0] > COLLISION_TOLERANCE else None


def open_pieces(solid: Solid, hob: HobBody, swivel: float, pieces: list) -> list:
    """The pieces X alone does not settle from their two ends (x_alone holds between them)."""
    reach = x_reach(hob, swivel, solid)
    centred = [tuple(centres(*point, swivel) for point in ends(a, b)) for a, b in pieces]
    return [piece for piece, (one, two) in zip(pieces, centred) if x_alone(one, two, reach) > LIMIT]


def ends(a: dict, b: dict) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """A piece's ends as machine (X, Y, Z) (mm; an axis not given at 0, as paths does)."""
    one, two = (tuple(point.get(axis, 0.0) for axis in AXES) for point in (a, b))
    return (one[0], one[1], one[2]), (two[0], two[1], two[2])


def piece_reaches(solid: Solid, hob: HobBody, swivel: float, poses: list, counted: list[int]) -> bool:
    """Whether the bounds of the module leave the hob possibly deeper than the tolerance less
    SLACK somewhere on one piece (poses: hob centres, DIN, mm, evenly spaced): exact samples at
    the solid's heights for the poses within two of an interval X alone does not settle."""
    extent, reach = hob.extent(swivel), x_reach(hob, swivel, solid)
    across = [x_alone(one, two, reach) for one, two in zip(poses, poses[1:])]
    if max(across) <= LIMIT:
        return False
    side = [overlap_side(cz, extent, solid) for _, _, cz in poses]
    wanted = {j for i, bound in enumerate(across) if bound > LIMIT for j in range(i - 1, i + 3)}
    found = [_pose_samples(solid, hob, swivel, pose, extent, reach) if i in wanted and not side[i]
             else (-math.inf, x_alone(pose, pose, reach) if not side[i] else -math.inf, 0)
             for i, pose in enumerate(poses)]
    counted[0] += sum(count for _, _, count in found)
    return max(interval_bounds([bounds[:2] for bounds in found], across, side)) > LIMIT


def _pose_samples(solid: Solid, hob: HobBody, swivel: float, pose: tuple, extent: float,
                  reach: tuple) -> tuple[float, float, int]:
    """(L, U, sections worked out) of one pose from its exact distances at the solid's heights
    within its reach (U no more than X alone allows)."""
    cx, cy, cz = pose
    heights, by_x = solid.heights, x_alone(pose, pose, reach)
    first, last = bisect_left(heights, cz - extent), bisect_right(heights, cz + extent)
    if last <= first:
        return -math.inf, by_x, 0
    found = nearest_radii(hob, swivel, cx, cy, cz, heights[first:last])
    deepest, bound = pose_bound(heights, solid.radius, first, found, found,
                                (max(solid.z_low, cz - extent), min(solid.z_high, cz + extent)))
    return deepest, min(bound, by_x), last - first
