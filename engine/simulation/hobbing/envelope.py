"""The hob as the simulation sees it: its tip cylinder (radius d_a0/2, length L, end faces
included), the axis in the Y–Z plane swivelled by A about X (reference §A6, §B7). Every hob
point lies within that solid, so what the cylinder does not touch, the hob does not touch.

The blank, its units, the fixture and the tailstock are all solids of revolution about the
work axis, so a hob pose meets them where, at some height z, the hob comes closer to the work
axis than the solid's radius. `nearest_radius` gives that closest distance at one height: the
horizontal slice of the (convex) cylinder is convex and the distance from the work axis is a
convex function, so along the slice's one free coordinate (dy, the slice's Y from the centre)
the minimum is where the derivative changes sign, found by Newton's method kept inside a
bracket that halves when a step leaves it. Plain floats (math): the simulation needs no numpy,
so proving one gear starts without importing it (issue 28). Exact to well below a micrometre,
not sampled.

The shift axis Y rides on the swivel head: Y moves the hob along its own axis, so the
generating zone stays where X and Z put it and a different part of the hob reaches it."""
from __future__ import annotations

import math
from dataclasses import dataclass

FREE_STEPS = 8             # Newton's steps from the last height's dy before the safe way is taken
STEP_LIMIT = 60            # Newton or halving steps in the bracket (it halves at least every other one)
DY_TOLERANCE = 1e-7        # mm: the free coordinate is found this closely (the distance to ~1e-12 mm)
THIN = 1e-12               # mm: a slice this thin (a tangent plane) has no interior to step in
UPRIGHT = 1e-12            # the sine of a swivel this small is taken as 0 (as the numpy version does)


@dataclass(frozen=True, slots=True)
class HobBody:
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


def nearest_radius(hob: HobBody, swivel: float, cx: float, cy: float, cz: float, height: float) -> float:
    """The least distance from the work axis (mm) of the hob's points at `height` with its centre
    at (cx, cy, cz); inf where the hob has no point at that height."""
    return nearest_radii(hob, swivel, cx, cy, cz, [height])[0]


def nearest_radii(hob: HobBody, swivel: float, cx: float, cy: float, cz: float, heights) -> list[float]:
    """nearest_radius at each of `heights` for one pose. The hob's section by the plane dz above
    its centre: a point of it at dy (along Y from the centre) lies q = s·dy − c·dz across the
    cylinder (s, c: sine and cosine of the swivel), so it spans X = cx ± w, w = √(R² − q²), and the
    end faces bound dy to |c·dy + s·dz| ≤ L/2. Its squared distance from the work axis,
    (cx − w)₊² + (cy + dy)², is convex in dy. Each height takes Newton's steps from the last
    height's dy while they stay inside (two or three: the distance is nearly a parabola in dy),
    else the safe way (Slice.bracketed). Written out in one loop: this is the simulation's inner
    loop (several thousand sections a program)."""
    a = math.radians(swivel)
    section = Slice(math.sin(a), math.cos(a), hob.radius, cx, cy)
    s, c, r2 = section.s, section.c, section.r2
    found, guess = [], -cy
    for height in heights:
        dz = height - cz
        low, high = section.span(dz, hob.half_length)
        if low > high:
            found.append(math.inf)
            continue
        dy, done = (low if guess < low else high if guess > high else guess), False
        for _ in range(FREE_STEPS):
            q = s * dy - c * dz
            w2 = r2 - q * q
            if w2 <= THIN:
                break
            w = math.sqrt(w2)
            gap = cx - w
            if gap > 0:
                sq = s * q
                step = dy - (gap * sq / w + cy + dy) / (1.0 + sq * sq / w2 + gap * s * s * r2 / (w2 * w))
            else:
                step = -cy
            if not low < step < high:
                break
            if -DY_TOLERANCE < step - dy < DY_TOLERANCE:
                dy, done = step, True
                break
            dy = step
        guess = dy if done else section.bracketed(dz, low, high)
        q = s * guess - c * dz
        found.append(math.sqrt(max(cx - math.sqrt(max(r2 - q * q, 0.0)), 0.0) ** 2 + (cy + guess) ** 2))
    return found


class Slice:
    """One pose's sections: the swivel's sine and cosine, the hob's radius, the centre's X and Y."""

    __slots__ = ("s", "c", "r", "r2", "cx", "cy")

    def __init__(self, s: float, c: float, r: float, cx: float, cy: float) -> None:
        s = s if abs(s) > UPRIGHT else 0.0    # an upright hob: the section's width does not vary along dy
        self.s, self.c, self.r, self.r2, self.cx, self.cy = s, c, r, r * r, cx, cy

    def span(self, dz: float, half_length: float) -> tuple[float, float]:
        """(low, high) of dy at dz; low > high where the hob has no point there."""
        s, c = self.s, self.c
        low, high = (-half_length - s * dz) / c, (half_length - s * dz) / c
        if s:
            first, second = (c * dz - self.r) / s, (c * dz + self.r) / s
            return max(low, min(first, second)), min(high, max(first, second))
        return (low, high) if abs(dz) <= self.r else (high, low - 1.0)

    def squared(self, dz: float, dy: float) -> float:
        q = self.s * dy - self.c * dz
        half = math.sqrt(max(self.r2 - q * q, 0.0))
        return max(self.cx - half, 0.0) ** 2 + (self.cy + dy) ** 2

    def bracketed(self, dz: float, low: float, high: float) -> float:
        """An end whose slope points out of the interval, else the root of the slope: Newton's steps
        inside the bracket where the slope changes sign, halving it when a step would leave it."""
        if high - low <= THIN or self.derivatives(dz, low)[0] >= 0:
            return low
        if self.derivatives(dz, high)[0] <= 0:
            return high
        dy = (low + high) / 2
        for _ in range(STEP_LIMIT):
            slope, curvature = self.derivatives(dz, dy)
            if slope > 0:
                high = dy
            else:
                low = dy
            step = dy - slope / curvature if 0 < curvature < math.inf else math.nan
            step = step if low < step < high else (low + high) / 2
            if abs(step - dy) < DY_TOLERANCE:
                return step
            dy = step
        return dy

    def derivatives(self, dz: float, dy: float) -> tuple[float, float]:
        """Half the first and second derivative of the squared distance along dy: cy + dy +
        (cx − w)·s·q/w and 1 + s²q²/w² + (cx − w)·s²R²/w³ where the hob's side faces the axis
        (the first is ±inf at the section's rim, pointing inwards)."""
        s = self.s
        q = s * dy - self.c * dz
        w2 = self.r2 - q * q
        w = math.sqrt(max(w2, 0.0))
        gap = self.cx - w
        if gap <= 0:
            return self.cy + dy, 1.0
        if w <= THIN:
            return (math.copysign(math.inf, s * q) if s * q else self.cy + dy), math.inf
        sq = s * q
        return gap * sq / w + self.cy + dy, 1.0 + sq * sq / w2 + gap * s * s * self.r2 / (w2 * w)
