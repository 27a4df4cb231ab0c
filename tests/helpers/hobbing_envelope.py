"""The hob as a solid cylinder in 3-D, swept along a move, against solids of revolution about the
work axis (blank units, root cone, fixture, tailstock), for the reference checks of issue 14.

Frame: DIN 66217 (reference §A7). The swivel η turns the hob axis about X: u = (0, cos η, sin η); the
shift Y slides the hob along that axis (§A6), so the body occupies t ∈ [Y − L/2, Y + L/2] along u
from the centre (X, 0, Z), and within r0 of it: a point is centre + t·u + v·e_x + w·n with
n = (0, −sin η, cos η), v² + w² ≤ r0².

Intrusion = the largest depth by which any point of the hob lies inside the solid (depth = distance to
the solid's boundary: min of the cone/cylinder wall along its normal and both faces). Why it is found
exactly, not sampled: for fixed (t, w) the point nearest the work axis has |x| = max(0, |X| − √(r0² − w²)),
convex in (X, w); ρ = √(x² + y²) is then convex and the depth concave in (move fraction, t, w). A
concave function's maximum over a convex domain has no false local maxima, so golden-section over the
move fraction and over w, with the exact maximum over t (endpoints, the wall's own maximum, and where
the wall meets a face: a quadratic), finds it to 1e-4 mm. A move that also swivels is checked at
steps of at most 0.25° of η.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

GOLDEN = (math.sqrt(5) - 1) / 2
RESOLUTION = 5e-4       # mm of bracket left by the golden-section searches (depth is 1-Lipschitz)
_FOUND: dict = {}       # (sweep, solid, r0, length) → intrusion: the same DIN moves recur across machines


@dataclass(frozen=True)
class Solid:
    """Radius `radius` at height `z_ref`, changing by `slope` (tan δ) per mm of Z, between the faces."""
    radius: float
    bottom: float
    top: float
    slope: float = 0.0
    z_ref: float = 0.0


@dataclass(frozen=True)
class Sweep:
    """The hob centre moving linearly from (x0, z0) to (x1, z1) at swivel eta (degrees); its shift
    lies in [y_low, y_high] at the start and at the end (a range when only a parameter names it)."""
    x0: float
    z0: float
    x1: float
    z1: float
    eta: float
    y_start: tuple = (0.0, 0.0)
    y_end: tuple = (0.0, 0.0)


def intrusion(sweep: Sweep, solid: Solid, r0: float, length: float) -> float:
    """How deep (mm) the hob reaches into the solid anywhere along the move (≤ 0: clear)."""
    return float(intrusions([sweep], [solid], r0, length)[0])


def intrusions(sweeps: list[Sweep], solids: list[Solid], r0: float, length: float) -> np.ndarray:
    """`intrusion` for many (sweep, solid) pairs at once (remembered: the same DIN moves recur)."""
    keys = [(sweep, solid, r0, length) for sweep, solid in zip(sweeps, solids)]
    missing = list(dict.fromkeys(k for k in keys if k not in _FOUND))
    for still in (True, False):
        group = [k for k in missing if _still(k[0]) == still]
        if group:
            found = _intrusions([k[0] for k in group], [k[1] for k in group], r0, length, still)
            _FOUND.update(zip(group, found.tolist()))
    return np.array([_FOUND[k] for k in keys], float)


def _still(sweep: Sweep) -> bool:
    return (sweep.x0, sweep.z0, sweep.y_start) == (sweep.x1, sweep.z1, sweep.y_end)


def _intrusions(sweeps: list[Sweep], solids: list[Solid], r0: float, length: float, still: bool) -> np.ndarray:
    """Pairs clear by their bounding box skip the search; a hob standing still needs no search along the move."""
    p = {name: np.array([getattr(s, name) for s in sweeps], float) for name in ("x0", "z0", "x1", "z1", "eta")}
    for name, index in (("ylo0", 0), ("yhi0", 1)):
        p[name] = np.array([s.y_start[index] for s in sweeps], float)
    for name, index in (("ylo1", 0), ("yhi1", 1)):
        p[name] = np.array([s.y_end[index] for s in sweeps], float)
    for name in ("radius", "bottom", "top", "slope", "z_ref"):
        p[name] = np.array([getattr(s, name) for s in solids], float)
    result = np.full(len(sweeps), -math.inf)
    near = _near(p, r0, length)
    if near.any():
        result[near] = _search({k: v[near] for k, v in p.items()}, r0, length, still)
    return result


def _near(p: dict, r0: float, length: float) -> np.ndarray:
    """Pairs whose hob bounding box can reach the solid (the others are clear by more than 0)."""
    eta = np.radians(p["eta"])
    reach_z = r0 * np.abs(np.cos(eta)) + (length / 2 + np.maximum.reduce(
        [np.abs(p[k]) for k in ("ylo0", "yhi0", "ylo1", "yhi1")])) * np.abs(np.sin(eta))
    widest = np.maximum(*(p["radius"] + p["slope"] * (p[f] - p["z_ref"]) for f in ("bottom", "top")))
    x_clear = np.minimum(np.abs(p["x0"]), np.abs(p["x1"])) - r0 >= widest
    z_low, z_high = np.minimum(p["z0"], p["z1"]) - reach_z, np.maximum(p["z0"], p["z1"]) + reach_z
    return ~(x_clear | (z_low >= p["top"]) | (z_high <= p["bottom"]))


def _golden_max(f, low: np.ndarray, high: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """Maximum of concave functions (vectorised) on [low, high], to RESOLUTION mm (`scale` mm per unit
    of the argument)."""
    width = float(np.max(high - low)) * scale if low.size else 0.0
    steps = max(1, math.ceil(math.log(max(width, RESOLUTION) / RESOLUTION) / -math.log(GOLDEN)))
    a, b = low.copy(), high.copy()
    x1, x2 = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    f1, f2 = f(x1), f(x2)
    for _ in range(steps):
        right = f1 < f2
        a = np.where(right, x1, a)
        b = np.where(right, b, x2)
        x1, x2, f1, f2 = (np.where(right, x2, b - GOLDEN * (b - a)), np.where(right, a + GOLDEN * (b - a), x1),
                          np.where(right, f2, np.nan), np.where(right, np.nan, f1))
        fresh = f(np.where(right, x2, x1))
        f1, f2 = np.where(right, f1, fresh), np.where(right, fresh, f2)
    return np.maximum.reduce([f1, f2, f(low), f(high)])


def _search(p: dict, r0: float, length: float, still: bool) -> np.ndarray:
    eta = np.radians(p["eta"])
    ce, se = np.cos(eta), np.sin(eta)

    def over_w(fraction: np.ndarray) -> np.ndarray:
        x = p["x0"] + fraction * (p["x1"] - p["x0"])
        zc = p["z0"] + fraction * (p["z1"] - p["z0"])
        t_low = p["ylo0"] + fraction * (p["ylo1"] - p["ylo0"]) - length / 2
        t_high = p["yhi0"] + fraction * (p["yhi1"] - p["yhi0"]) + length / 2

        def at_w(w: np.ndarray) -> np.ndarray:
            nearest_x = np.maximum(0.0, np.abs(x) - np.sqrt(np.maximum(r0 * r0 - w * w, 0.0)))
            return _best_along_t(nearest_x, zc + w * ce, -w * se, t_low, t_high, ce, se, p)
        return _golden_max(at_w, np.full(x.shape, -r0), np.full(x.shape, r0))

    count = p["x0"].shape
    if still:
        return over_w(np.zeros(count))
    travel = np.hypot(p["x1"] - p["x0"], p["z1"] - p["z0"]) + np.maximum(np.abs(p["ylo1"] - p["ylo0"]),
                                                                         np.abs(p["yhi1"] - p["yhi0"]))
    return _golden_max(over_w, np.zeros(count), np.ones(count), max(float(np.max(travel)), 1.0))


def _depth(x, y, z, p: dict) -> np.ndarray:
    wall = (p["radius"] + p["slope"] * (z - p["z_ref"]) - np.sqrt(x * x + y * y)) / np.sqrt(1 + p["slope"] ** 2)
    return np.minimum(wall, np.minimum(z - p["bottom"], p["top"] - z))


def _best_along_t(x, z_a, y_a, t_low, t_high, ce, se, p: dict) -> np.ndarray:
    """Exact maximum over t of the depth of the points (x, y_a + t·cos η, z_a + t·sin η)."""
    cos_d = 1 / np.sqrt(1 + p["slope"] ** 2)
    candidates = [t_low, t_high]
    k = np.clip(p["slope"] * se / ce, -0.999, 0.999)
    candidates.append((k * x / np.sqrt(1 - k * k) - y_a) / ce)          # the wall's own maximum
    with np.errstate(divide="ignore", invalid="ignore"):
        candidates.append(((p["bottom"] + p["top"]) / 2 - z_a) / se)    # midway between the faces
        wall_at_a = cos_d * (p["radius"] + p["slope"] * (z_a - p["z_ref"]))
        for alpha, beta in ((wall_at_a - (z_a - p["bottom"]), (cos_d * p["slope"] - 1) * se),
                            (wall_at_a - (p["top"] - z_a), (cos_d * p["slope"] + 1) * se)):
            # alpha + beta·t = cos δ·√(x² + (y_a + t·cos η)²), squared
            qa = beta * beta - cos_d ** 2 * ce * ce
            qb = alpha * beta - cos_d ** 2 * y_a * ce
            qc = alpha * alpha - cos_d ** 2 * (x * x + y_a * y_a)
            root = np.sqrt(qb * qb - qa * qc)
            linear = np.abs(qa) < 1e-12
            candidates += [np.where(linear, -qc / (2 * qb), (-qb + root) / qa),
                           np.where(linear, -qc / (2 * qb), (-qb - root) / qa)]
    best = np.full(x.shape, -np.inf)
    for t in candidates:
        t = np.clip(np.where(np.isfinite(t), t, t_low), t_low, t_high)
        best = np.maximum(best, _depth(x, y_a + t * ce, z_a + t * se, p))
    return best


SWIVEL_STEP = 0.25   # degrees of A between the hob envelopes checked on a move that swivels


def shift_limits(nc, machine) -> tuple:
    """The Y range the program's own G25/G26 allow (DIN): where a shift set from a parameter can be."""
    values = [machine.din("Y", b.words["Y"]) for b in nc.blocks if {25, 26} & set(b.g) and "Y" in b.words]
    values = [v for v in values if isinstance(v, float)]
    return (min(values), max(values)) if values else (0.0, 0.0)


def known_xz(move) -> bool:
    return all(isinstance(move.start[a], float) for a in "XZ")


def move_sweeps(move, swivel: float, limits: tuple) -> list[Sweep]:
    """The hob envelopes of a move read in the DIN frame: its centre X/Z from start to end, its shift
    Y (a parameter: anywhere within `limits`; never programmed: 0) and its swivel (a move that turns
    A: every SWIVEL_STEP between; A not yet programmed: `swivel`, the gear's)."""
    ys = [(v, v) if isinstance(v, float) else (0.0, 0.0) if v is None else limits
          for v in (move.start["Y"], move.end["Y"])]
    a0, a1 = (move.start["A"], move.end["A"])
    etas = [a1 if isinstance(a1, float) else swivel]
    if isinstance(a0, float) and isinstance(a1, float) and a0 != a1:
        count = math.ceil(abs(a1 - a0) / SWIVEL_STEP)
        etas = [a0 + (a1 - a0) * k / count for k in range(count + 1)]
    return [Sweep(move.start["X"], move.start["Z"], move.end["X"], move.end["Z"], eta, *ys) for eta in etas]


def hob_depths(pairs: list, swivel: float, r0: float, length: float, limits: tuple) -> list[float]:
    """For each (DIN move, Solid): how deep the hob reaches into the solid during the move."""
    flat, owner = [], []
    for index, (move, solid) in enumerate(pairs):
        for sweep in move_sweeps(move, swivel, limits):
            flat.append((sweep, solid))
            owner.append(index)
    depth = intrusions([s for s, _ in flat], [b for _, b in flat], r0, length) if flat else []
    found = [-math.inf] * len(pairs)
    for index, value in zip(owner, depth):
        found[index] = max(found[index], float(value))
    return found


def root_section_centre(root_radius: float, r0: float, cone: float, eta: float) -> float:
    """Centre distance at which the hob's tip section in the plane Y = 0 (an ellipse r0 × r0/cos η)
    touches the root line x = root_radius + z·tan δ at z = 0: its support distance along the line's
    normal (cos δ, −sin δ) is r0·√(cos²δ + sin²δ/cos²η)."""
    d, e = math.radians(cone), math.radians(eta)
    return root_radius + r0 * math.sqrt(math.cos(d) ** 2 + math.sin(d) ** 2 / math.cos(e) ** 2) / math.cos(d)
