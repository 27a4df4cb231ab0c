"""The hob as a solid cylinder in 3-D, swept along a move, against solids of revolution about the
work axis (blank units, root cone, fixture, tailstock), for the reference checks of issue 14.

Frame: DIN 66217 (reference §A7). The swivel η turns the hob axis about X: u = (0, cos η, sin η); the
shift Y slides the hob along that axis (§A6), so the body occupies t ∈ [Y − L/2, Y + L/2] along u
from the centre (X, 0, Z), and within r0 of it: a point is centre + t·u + v·e_x + w·n with
n = (0, −sin η, cos η), v² + w² ≤ r0² (mm, degrees).

Intrusion = the largest depth by which any point of the hob lies inside the solid (depth = distance to
the solid's boundary: min of the cone/cylinder wall along its normal and both faces), over the whole
move: the centre at fraction f ∈ [0, 1] of it, the shift range moving linearly with f.

Why the answer is proven, not sampled (issue 28):
* Concave. For fixed (f, t, w) the point nearest the work axis has |x| = max(0, |X(f)| − √(r0² − w²)),
  convex in (f, w); ρ = √(x² + y²) is then convex and the depth (a minimum of the wall, c·(R + k·z − ρ),
  and the faces, all concave) is concave in (f, t, w) over a convex domain (t between bounds linear in f).
  Its maximum over t (f, w fixed) is exact: at an end of t's range, the wall's own maximum or where the
  wall meets a face (a quadratic). ψ(f, w) = that maximum is concave, and so is φ(f) = max_w ψ(f, w).
* Bounded from above by values alone. For a concave g sampled at x_{i−1} < x_i < x_{i+1} < x_{i+2}, on
  [x_i, x_{i+1}] g lies below the secant through x_{i−1}, x_i extended forward and below the secant
  through x_{i+1}, x_{i+2} extended back (slopes of a concave function fall): the larger of the lower
  of the two lines over the cell bounds g there (at the ends of the range the one line left does).
  Values known only to ±ε (g ≤ ĝ + ε, g ≥ ĝ) move that bound by at most 2ε within one cell.
* Grid section (_grid_max): each round samples a bracket at GRID + 1 points, bounds every cell so, and
  keeps the cells whose bound reaches the best value seen (a cell bounded below it cannot hold the
  maximum, the best value being that of a real point); the bracket shrinks to those cells (about two
  of GRID at a sharp maximum; at a flat one the bound meets the value). It stops when the largest
  bound is within TOLERANCE/4 (over w) or TOLERANCE (over f, the inner gap counted) of the best value.
  The intrusion returned is that best value: the depth of a point of the hob (never deeper than the
  truth) and at most TOLERANCE mm shallower. A hob standing still needs no f; a move that also
  swivels is checked at steps of at most 0.25° of η (move_sweeps).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TOLERANCE = 1e-6        # mm: the intrusion is proven within this below the truth, never above it
GRID = 16               # cells per round of the grid section (a sharp maximum's bracket shrinks ~8×)
ROUNDS = 60             # rounds at most; a search not within TOLERANCE by then is an error, not a guess
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


def _grid_max(f, low: np.ndarray, high: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """(best, gap): the largest value of concave functions on [low, high] (one row each), the best
    value of a point evaluated and the proven bound on how far the maximum lies above it. `f` maps
    arguments (rows × points) to (values, their error ε ≥ 0, per row)."""
    low, high = low.astype(float), high.astype(float)
    best = np.full(low.shape, -np.inf)
    steps = np.linspace(0.0, 1.0, GRID + 1)
    for _ in range(ROUNDS):
        value, error = f(low[:, None] + (high - low)[:, None] * steps)
        best = np.maximum(best, value.max(axis=1))
        bound = _cell_bounds(value) + 2 * error[:, None]
        gap = np.maximum(bound.max(axis=1) - best, 0.0)
        if (gap <= tolerance).all():
            return best, gap
        kept = bound >= best[:, None] - 1e-12
        first, last = kept.argmax(axis=1), GRID - 1 - kept[:, ::-1].argmax(axis=1)
        low, high = low + (high - low) * first / GRID, low + (high - low) * (last + 1) / GRID
    raise AssertionError(f"hob envelope: the grid section did not close to {tolerance} mm (gap {gap.max()})")


def _cell_bounds(g: np.ndarray) -> np.ndarray:
    """Upper bound of a concave function on each cell between neighbouring samples (rows × GRID), in
    units of the cell: below the secant from the left, g_i + (g_i − g_{i−1})·s, and below the one from
    the right, g_{i+1} + (g_{i+1} − g_{i+2})·(1 − s), s ∈ [0, 1] across the cell."""
    inf = np.full(g[:, :1].shape, np.inf)
    left_slope = np.concatenate([inf * np.nan, g[:, 1:-1] - g[:, :-2]], axis=1)        # per cell i
    right_slope = np.concatenate([g[:, 1:-1] - g[:, 2:], inf * np.nan], axis=1)
    a, b = g[:, :-1], g[:, 1:]
    left = lambda s: np.where(np.isnan(left_slope), np.inf, a + left_slope * s)        # noqa: E731
    right = lambda s: np.where(np.isnan(right_slope), np.inf, b + right_slope * (1 - s))   # noqa: E731
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = np.clip((b + right_slope - a) / (left_slope + right_slope), 0.0, 1.0)
    bound = np.maximum(np.minimum(left(0.0), right(0.0)), np.minimum(left(1.0), right(1.0)))
    meet = np.minimum(left(cross), right(cross))
    bound = np.maximum(bound, np.where(np.isfinite(meet), meet, -np.inf))
    return np.maximum(bound, np.maximum(a, b))


def _search(p: dict, r0: float, length: float, still: bool) -> np.ndarray:
    """φ's maximum over the move fraction (still: at f = 0), each φ(f) by a grid section over w."""
    count = p["x0"].shape[0]
    if still:
        return _over_w(p, np.zeros((count, 1)), r0, length)[0][:, 0]
    over_f = lambda fraction: _over_w(p, fraction, r0, length)   # noqa: E731
    return _grid_max(over_f, np.zeros(count), np.ones(count), TOLERANCE)[0]


def _over_w(p: dict, fraction: np.ndarray, r0: float, length: float) -> tuple[np.ndarray, np.ndarray]:
    """φ(f) for each row's fractions (rows × points): (values, the largest gap of a row)."""
    rows, points = fraction.shape
    q = {k: np.repeat(v, points)[:, None] for k, v in p.items()}
    f = fraction.reshape(-1, 1)
    x = q["x0"] + f * (q["x1"] - q["x0"])
    zc = q["z0"] + f * (q["z1"] - q["z0"])
    t_low = q["ylo0"] + f * (q["ylo1"] - q["ylo0"]) - length / 2
    t_high = q["yhi0"] + f * (q["yhi1"] - q["yhi0"]) + length / 2
    eta = np.radians(q["eta"])
    ce, se = np.cos(eta), np.sin(eta)

    def at_w(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        nearest_x = np.maximum(0.0, np.abs(x) - np.sqrt(np.maximum(r0 * r0 - w * w, 0.0)))
        return _best_along_t(nearest_x, zc + w * ce, -w * se, t_low, t_high, ce, se, q), np.zeros(len(w))
    best, gap = _grid_max(at_w, np.full(rows * points, -r0), np.full(rows * points, r0), TOLERANCE / 4)
    return best.reshape(rows, points), gap.reshape(rows, points).max(axis=1)


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
