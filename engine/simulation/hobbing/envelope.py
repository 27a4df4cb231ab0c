"""The hob as the simulation sees it: its tip cylinder (radius R = d_a0/2, length L, end faces
included), the axis in the Y–Z plane swivelled by A about X (reference §A6, §B7). Every hob
point lies within that solid, so what the cylinder does not touch, the hob does not touch.

The blank, its units, the fixture and the tailstock are all solids of revolution about the
work axis, so a hob pose meets them where, at some height z, the hob comes closer to the work
axis than the solid's radius. `nearest_radius` gives that closest distance at one height,
exactly (issue 28), not searched:

* The hob. Centre C = (cx, cy, cz), axis u = (0, c, s) with s, c = sin A, cos A (mm, DIN).
  A point p lies in the hob where |(p − C)·u| ≤ L/2 (between the end faces) and its distance
  from the axis is at most R.
* Its horizontal slice at height z, dz = z − cz. Write p − C = (ξ, dy, dz). The radial
  directions are X and e = (0, −s, c); along e the point lies −q, q = s·dy − c·dz (mm), so the
  mantle holds ξ² + q² ≤ R²: in the (ξ, dy) plane an ellipse about (0, dy₀), dy₀ = c·dz/s,
  with semi-axes a = R along X and b = R/|s| along Y (for s = 0, the strip |dz| ≤ R). The end
  faces, |c·dy + s·dz| ≤ L/2, cut it between two lines of constant dy.
* The nearest point to the work axis (x = y = 0). At dy the slice spans X = cx ± w,
  w = √(R² − q²), so the squared distance is g(dy) = (cx − w)₊² + (cy + dy)² (mm²), convex in
  dy (the slice is convex). Without the end faces its least value is at dy* = −cy where the
  axis passes through the ellipse (distance 0 there), else at the foot of the normal from the
  axis's point P = (−cx, −cy − dy₀) (from the ellipse's centre): the foot is
  (a²Pξ/(t + a²), b²Py/(t + b²)), t (mm²) the root of
      F(t) = (a·Pξ/(t + a²))² + (b·Py/(t + b²))² − 1,
  which falls and is convex for t > 0, so Newton's steps from a t where F ≥ 0, such as
  t₀ = max(0, a|Pξ| − a², b|Py| − b²) (each term alone is 1 there), rise to the root and never
  pass it. dy* = −cy − Py·t/(t + b²) (the difference written out: b is large for a nearly level
  hob, and dy₀ with it).
* The end faces. g is convex, so over the band between them its least value lies at dy*
  clamped into the band; the distance is √g there (mm), to about 1e-10 mm.

Plain floats (math): the simulation needs no numpy, so proving one gear starts without importing
it; engine.simulation.hobbing.envelope_arrays computes the same for a batch's many sections.

The shift axis Y rides on the swivel head: Y moves the hob along its own axis, so the
generating zone stays where X and Z put it and a different part of the hob reaches it."""
from __future__ import annotations

import math

import msgspec

UPRIGHT = 1e-12            # the sine of a swivel this small is taken as 0: the slice is a strip
ROOT_TOLERANCE = 1e-9      # F(t) within this of 0: dy* is off by ~1e-9·cx, the distance by far less
STEP_LIMIT = 60            # Halley's or Newton's steps at most (one to three suffice: the start is near)


class HobBody(msgspec.Struct, frozen=True):
    """The hob as the simulation sees it: a cylinder of its tip radius and length (mm)."""
    radius: float          # d_a0/2
    half_length: float     # L/2

    def extent(self, swivel: float) -> float:
        """How far above and below its centre the swivelled cylinder reaches along Z."""
        a = math.radians(swivel)
        return self.radius * abs(math.cos(a)) + self.half_length * abs(math.sin(a))


def centres(x: float, y: float, z: float, swivel: float) -> tuple[float, float, float]:
    """The hob centre in DIN coordinates for machine positions X, Y (along the hob axis), Z."""
    a = math.radians(swivel)
    return x, y * math.cos(a), z + y * math.sin(a)


def sine_cosine(swivel: float) -> tuple[float, float]:
    """sin A and cos A of the hob's body at swivel A (degrees), the sine of a level hob exactly 0.
    A cylinder has no direction: swivelled beyond ±90° it is the cylinder at A ∓ 180°, so the pair
    is taken with cos A ≥ 0 (the band between the end faces divides by it; with cos A < 0 every
    slice read as empty, and the hob met nothing)."""
    a = math.radians(swivel)
    s, c = math.sin(a), math.cos(a)
    if c < 0:
        s, c = -s, -c
    return (s if abs(s) > UPRIGHT else 0.0), c


def nearest_radius(hob: HobBody, swivel: float, cx: float, cy: float, cz: float, height: float) -> float:
    """The least distance from the work axis (mm) of the hob's points at `height` with its centre
    at (cx, cy, cz); inf where the hob has no point at that height."""
    return nearest_radii(hob, swivel, cx, cy, cz, [height])[0]


def nearest_radii(hob: HobBody, swivel: float, cx: float, cy: float, cz: float, heights) -> list[float]:
    """nearest_radius at each of `heights` for one pose (the module's formulation)."""
    nearest = Slices.of(hob, swivel, cx, cy).nearest
    return [nearest(height - cz) for height in heights]


class Slices(msgspec.Struct, frozen=True):
    """One pose's horizontal slices: of the formulation's terms, all but those of dz are fixed
    per pose and worked out once here (a pose spans tens of heights, a gear's proof some 4,000
    sections, issue 28). The solids are of revolution about the work axis, so a centre at −cx
    (across the axis) is as far as one at cx: cx ≥ 0 here, and Pξ = cx at every height. The
    per-height steps pick the greater or lesser of two floats by comparison, with max's and
    min's result, and square by multiplying, as envelope_arrays' numpy does (the calls of max,
    min and x ** 2 cost more than the arithmetic)."""
    s: float               # sin A, 0 for an upright hob (sine_cosine)
    c: float               # cos A ≥ 0
    r: float               # R = a, the ellipse's semi-axis along X (mm)
    half: float            # L/2 (mm)
    cx: float              # |cx| (mm)
    cy: float              # mm
    edge: float            # R signed as s (mm): the ellipse spans dy from (c·dz − edge)/s to (c·dz + edge)/s
    b: float               # R/|s| (mm), the semi-axis along Y; inf for an upright hob (never read)
    a2: float              # a² (mm²)
    b2: float              # b² (mm²)
    ap: float              # a·|Pξ| (mm²)
    x_floor: float         # a·|Pξ| − a² (mm²), the first term of ellipse_root's t₀
    x_share: float         # (|Pξ|/a)², X's share of the ellipse's equation at P

    @classmethod
    def of(cls, hob: HobBody, swivel: float, cx: float, cy: float) -> Slices:
        s, c = sine_cosine(swivel)
        r, cx = hob.radius, abs(cx)
        b = r / abs(s) if s else math.inf
        return cls(s, c, r, hob.half_length, cx, cy, math.copysign(r, s), b, r * r, b * b, r * cx,
                   r * cx - r * r, (cx / r) * (cx / r))

    def nearest(self, dz: float) -> float:
        """nearest_radius at dz = height − cz (mm): at dy* clamped into the band, where g is least."""
        low, high = self.band(dz)
        if low > high:
            return math.inf
        cdz = self.c * dz
        dy = self.unbounded_dy(cdz)
        dy = low if low > dy else dy            # max(dy, low)
        dy = high if high < dy else dy          # min(…, high)
        q = self.s * dy - cdz
        w = self.a2 - q * q                     # w² (mm²), 0 or less only at the ellipse's tips (rounding)
        gap = self.cx - math.sqrt(w) if w > 0.0 else self.cx
        gap = 0.0 if gap < 0.0 else gap
        across = self.cy + dy
        return math.sqrt(gap * gap + across * across)

    def band(self, dz: float) -> tuple[float, float]:
        """(low, high) of dy in the slice at dz: between the end faces and within the ellipse's
        (or the strip's) reach; low > high where the hob has no point there."""
        s, c, sdz = self.s, self.c, self.s * dz
        low, high = (-self.half - sdz) / c, (self.half - sdz) / c
        if not s:
            return (low, high) if abs(dz) <= self.r else (high, low - 1.0)
        near, far = (c * dz - self.edge) / s, (c * dz + self.edge) / s
        return (near if near > low else low), (far if far < high else high)

    def unbounded_dy(self, cdz: float) -> float:
        """dy of the slice's nearest point to the work axis, the end faces left out: −cy where the
        axis passes through the ellipse (or the strip), else the foot of the normal from it."""
        s, cy = self.s, self.cy
        if not s or self.cx <= 0.0:
            return -cy
        py = -cy - cdz / s                      # Py
        y_share = py / self.b
        if self.x_share + y_share * y_share <= 1.0:
            return -cy
        bp, b2 = self.b * abs(py), self.b2
        floor = bp - b2 if bp - b2 > self.x_floor else self.x_floor      # t₀ = max(a|Pξ| − a², b|Py| − b², 0)
        t = ellipse_root(self.a2, b2, self.ap, bp, 0.0 if floor < 0.0 else floor)
        return -cy - py * t / (t + b2)


def ellipse_root(a2: float, b2: float, ap: float, bp: float, floor: float) -> float:
    """The root t (mm²) of F above, for a point P outside the ellipse (a2, b2: a², b²; ap, bp:
    a·|Pξ|, b·|Py|, mm²): Halley's steps (step) from _start's bound, never below t₀ = floor
    (F ≥ 0 there), until |F| is within ROOT_TOLERANCE: one to three from that start."""
    t = _start(a2, b2, ap, bp, floor)
    for _ in range(STEP_LIMIT):
        ta, tb = t + a2, t + b2
        u, v = ap / ta, bp / tb
        u2, v2 = u * u, v * v
        f = u2 + v2 - 1.0
        if -ROOT_TOLERANCE <= f <= ROOT_TOLERANCE:
            return t
        t = t + step(f, u2 / ta + v2 / tb, u2 / (ta * ta) + v2 / (tb * tb))
        t = floor if floor > t else t           # max(t, floor)
    return t


def step(f: float, slope: float, bend: float) -> float:
    """How far t moves: Halley's step for F (slope = −F′/2, bend = F″/6), t − 2FF′/(2F′² − FF″),
    where it is at most twice Newton's step f/(2·slope), else Newton's (far from the root,
    where Halley's could run off)."""
    denominator = 4.0 * slope * slope - 3.0 * f * bend
    if denominator >= 2.0 * slope * slope:
        return 2.0 * f * slope / denominator
    return f / (2.0 * slope)


def _start(a2: float, b2: float, ap: float, bp: float, floor: float) -> float:
    """A lower bound of the root close to it. t₀ = floor (where F ≥ 0) bounds it below. Holding
    the smaller term of F at its value at t₀ and solving for the larger gives t₁ ≥ root (the
    held term only falls as t rises); one Newton's step back from t₁ lands at or below the root
    (F is convex), and close: the held term hardly changes on a long ellipse (b ≫ a: a nearly
    level hob). The larger of that and t₀."""
    u, v = ap / (floor + a2), bp / (floor + b2)
    if (v < 1.0) if u >= v else (u < 1.0):
        high = ap / math.sqrt(1.0 - v * v) - a2 if u >= v else bp / math.sqrt(1.0 - u * u) - b2
        u, v = ap / (high + a2), bp / (high + b2)
        back = high + (u * u + v * v - 1.0) / (2.0 * (u * u / (high + a2) + v * v / (high + b2)))
        return floor if floor > back else back  # max(back, floor)
    return floor
