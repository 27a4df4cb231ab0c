"""The hob envelope of engine.simulation.hobbing.envelope for many poses and heights at once,
with numpy: the same exact nearest point of each horizontal slice to the work axis (the
ellipse's foot of the normal by Newton's steps, clamped between the end faces), for every pose
and height together. A batch of gears follows hundreds of thousands of sections, about 0.5 µs
each so against 3.5 µs one by one in plain floats, but importing numpy costs a process about
85 ms of wall time (190 ms of CPU): a process follows its first sections in plain floats
(engine.simulation.hobbing.contact.MATH_SECTIONS, where the two break even)
and imports this module only after them, so one gear's command never loads numpy (issue 28).
The two agree to 1e-9 mm (tests/test_simulation_random.py, tests/test_simulation_envelope.py)."""
from __future__ import annotations

import numpy as np

from .envelope import ROOT_TOLERANCE, STEP_LIMIT, HobBody, sine_cosine

TANGENT_WIDTH = 1e-6   # mm: a slice narrower than this where the tangent is taken gives no tangent bound
SLACK = 1e-6           # mm a bound must clear a distance by to rule a slice out: a worked-out nearest
                       # distance is exact to ~1e-9 mm, not to the last bit, while a bound can be exact


def nearest_radius(hob: HobBody, swivel: float, cx, cy, cz, heights):
    """Per pose (cx, cy, cz: arrays of shape (P, 1)) and height (shape (P, W)): the least
    distance from the work axis of the hob's points at that height, inf where it has none."""
    return Sections(hob, swivel, cx, cz, heights).nearest(cy)


class Sections:
    """The slices of a set of poses at their heights: dz and the band of dy each spans (mm)."""

    def __init__(self, hob: HobBody, swivel: float, cx, cz, heights) -> None:
        s, c = sine_cosine(swivel)
        r = hob.radius
        dz = heights - cz
        sdz, cdz = s * dz, c * dz
        low, high = (-hob.half_length - sdz) / c, (hob.half_length - sdz) / c
        if s:
            first, second = (cdz - r) / s, (cdz + r) / s       # first < second where s > 0
            near, far = (first, second) if s > 0 else (second, first)
            low, high = np.maximum(low, near), np.minimum(high, far)
            empty = low > high
        else:
            empty = np.abs(dz) > r
        self.s, self.c, self.r, self.cx, self.dz = s, c, r, np.abs(cx), dz   # across the axis: as far (cx ≥ 0)
        self.cdz = cdz
        self.low, self.high, self.empty = low, np.where(empty, low, high), empty

    def nearest(self, cy, where=None):
        """The least distance of each slice from the work axis (mm), inf where it is empty; with
        `where` (a mask), of the slices it marks only, as a flat array."""
        s, c, r = self.s, self.c, self.r
        if where is None:
            cx, cy = self.cx + 0.0 * self.dz, cy + 0.0 * self.dz
            dz, cdz, low, high, empty = self.dz, self.cdz, self.low, self.high, self.empty
        else:
            cx, cy = _picked(self.cx, where), _picked(cy, where)
            dz, cdz, low, high, empty = (self.dz[where], self.cdz[where], self.low[where], self.high[where],
                                         self.empty[where])
        dy = np.minimum(np.maximum(unbounded_dy(s, c, r, cx, cy, dz), low), high)
        q = s * dy - cdz
        gap = np.maximum(cx - np.sqrt(np.maximum(r * r - q * q, 0.0)), 0.0)
        return np.where(empty, np.inf, np.sqrt(gap * gap + (cy + dy) ** 2))

    def bounds(self, cy) -> tuple:
        """(lower, upper) bounds (mm) of each slice's least distance from the work axis, with no
        nearest point worked out; inf where the slice is empty. The lower is the larger of two:
        * in X alone: the slice reaches no nearer the axis than cx − w, w its widest half-width
          √(R² − q²) at the least |q| over its band (q is linear in dy);
        * a half-plane holding it: w(dy) is concave, so below its tangent at d₀ (−cy clamped
          into the band, where w₀ > 0): the slice lies where x ≥ cx − w₀ − k·(dy − d₀),
          k = w′(d₀) = −s·q₀/w₀, and the axis is (cx − w₀ + k·(cy + d₀))/√(1 + k²) from that
          line's far side.
        The upper is the distance of one of its points: (cx − w₀, d₀)."""
        s, r, cdz, cx = self.s, self.r, self.cdz, self.cx
        q_low, q_high = s * self.low - cdz, s * self.high - cdz
        if s < 0:
            q_low, q_high = q_high, q_low
        least = np.maximum(np.maximum(q_low, -q_high), 0.0)      # 0 where q changes sign in the band
        in_x = cx - np.sqrt(np.maximum(r * r - least * least, 0.0))
        q0, w0, gap, across = self._point(cy)
        wide = w0 > TANGENT_WIDTH
        k = np.divide(-s * q0, w0, out=np.zeros(w0.shape), where=wide)
        tangent = np.where(wide, (gap + k * across) / np.sqrt(1.0 + k * k), 0.0)
        lower = np.maximum(in_x, tangent)          # an empty slice's does not matter: its distance is inf
        gap = np.maximum(gap, 0.0)
        return lower, np.where(self.empty, np.inf, np.sqrt(gap * gap + across ** 2))

    def _point(self, cy) -> tuple:
        """At d₀ (−cy clamped into the band): q₀, w₀ (the slice's half-width there), cx − w₀ and cy + d₀ (mm)."""
        d0 = np.minimum(np.maximum(-cy, self.low), self.high)
        q0 = self.s * d0 - self.cdz
        w0 = np.sqrt(np.maximum(self.r * self.r - q0 * q0, 0.0))
        return q0, w0, self.cx - w0, cy + d0

    def farther_than(self, cy, radius) -> bool:
        """Whether every slice lies at least `radius` (mm, per slice) from the work axis, by
        the lower of bounds, by SLACK. Where one may not, the nearest points are worked out."""
        return bool((self.bounds(cy)[0] >= radius + SLACK).all())


def _picked(values, where):
    """`values` (one per slice, or one per pose: shape (P, 1)) at the slices `where` marks, flat."""
    return values[where] if values.shape == where.shape else values[np.nonzero(where)[0], 0]


def unbounded_dy(s: float, c: float, r: float, cx, cy, dz):
    """envelope.Slices.unbounded_dy, elementwise (cx, cy and dz of one shape)."""
    dy = -cy
    if not s:
        return dy
    b = r / abs(s)
    px, py = cx, -cy - c * dz / s
    outside = np.flatnonzero((px > 0.0) & ((px / r) ** 2 + (py / b) ** 2 > 1.0))
    px, py, dy = px.ravel()[outside], py.ravel()[outside], dy.ravel()
    t = ellipse_root(r, b, px, np.abs(py))
    dy[outside] -= py * t / (t + b * b)
    return dy.reshape(dz.shape)


def ellipse_root(a: float, b: float, px, py):
    """envelope.ellipse_root elementwise (flat arrays of points |Pξ|, |Py| outside the ellipse of
    semi-axes a, b; envelope's takes a², b² and a·|Pξ|, which it works out once per pose): the same
    start and steps on every point, each one's t held from the first step its |F| is within
    ROOT_TOLERANCE (the points are not picked out step by step: a cut's few dozen cost more
    in picking than in stepping)."""
    a2, b2 = a * a, b * b
    ap, bp = a * px, b * py
    floor = np.maximum(np.maximum(ap - a2, bp - b2), 0.0)
    t = _start(a2, b2, ap, bp, floor)
    for _ in range(STEP_LIMIT):
        ta, tb = t + a2, t + b2
        u2, v2 = (ap / ta) ** 2, (bp / tb) ** 2
        f = u2 + v2 - 1.0
        going = np.abs(f) > ROOT_TOLERANCE
        if not going.any():
            break
        t = np.where(going, np.maximum(t + step(f, u2 / ta + v2 / tb, u2 / (ta * ta) + v2 / (tb * tb)), floor), t)
    return t


def step(f, slope, bend):
    """envelope.step elementwise."""
    denominator = 4.0 * slope * slope - 3.0 * f * bend
    return np.where(denominator >= 2.0 * slope * slope, 2.0 * f * slope / denominator, f / (2.0 * slope))


def _start(a2: float, b2: float, ap, bp, floor):
    """envelope._start elementwise."""
    u, v = ap / (floor + a2), bp / (floor + b2)
    with np.errstate(divide="ignore", invalid="ignore"):
        high = np.where(u >= v, ap / np.sqrt(1.0 - np.minimum(v * v, 1.0)) - a2,
                        bp / np.sqrt(1.0 - np.minimum(u * u, 1.0)) - b2)
        ha, hb = high + a2, high + b2
        u, v = ap / ha, bp / hb
        uu, vv = u * u, v * v
        back = high + (uu + vv - 1.0) / (2.0 * (uu / ha + vv / hb))
    return np.where(np.isfinite(back), np.maximum(back, floor), floor)
