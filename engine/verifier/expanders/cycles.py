"""The moves a lathe control makes for its multiple repetitive cycles, as pure geometry over
plain (x, z) points: X a diameter in mm, Z in mm, absolute (issue 27). The ISO expander (Fanuc/Haas
G70–G76) and the LinuxCNC expander (G70/G71/G76) read their words and call these; the moves
returned are what the verifier and the turning simulation follow.

Reference (docs/reference/iso-lathe.md): G71/G72 rough in passes of depth Δd (radius) parallel to
Z (G71) or X (G72) down to the finish contour offset by the allowances U (diameter) and W, each
pass ending at the offset contour, retracting by e at 45° and returning at rapid, then one pass
along the offset contour (Fanuc type I); G73 repeats the contour d times from the relief (i, k)
in to the allowances; G70 follows the contour itself; G74/G75 peck by Δk/Δi with a retract e;
G76 cuts a thread in passes whose depth grows as Δd·√n (constant chip area) down to the height
k less the finish allowance, then the finish pass, infeeding along the flank (angle a)."""
from __future__ import annotations

import math
from collections.abc import Callable

import msgspec

RAPID, FEED, CW, CCW, THREAD = 0, 1, 2, 3, 32
ARC_STEP = math.radians(5.0)    # an arc of the contour is followed by chords of at most 5° for roughing
EPS = 1e-9
MAX_PASSES = 2_000              # a cycle making more passes than this is refused by its caller: a G71 of
                                # 0.01 mm cuts over 20 mm of radius makes 2,000; more is a typo, and its moves
                                # would cost minutes and memory to prove (the adversary's G76 H99999999)


Swap = Callable[[float, float], tuple[float, float]]   # (x, z) <-> (level axis, cut axis)


def _same(x: float, z: float) -> tuple[float, float]:
    return x, z


def _swapped(x: float, z: float) -> tuple[float, float]:
    return z, x


class CycleError(ValueError):
    """A cycle whose words cannot make moves (a zero depth, a contour that does not go away from the start)."""


class Move(msgspec.Struct, frozen=True):
    """One block the control makes: its motion (RAPID, FEED, CW, CCW, THREAD), the end point, and
    for an arc its radius (mm, positive up to 180°)."""
    motion: int
    x: float
    z: float
    radius: float | None = None


def finish(start: tuple[float, float], contour: list[Move]) -> list[Move]:
    """G70: the contour as programmed, then back to the start point at rapid."""
    return [*contour, Move(RAPID, *start)]


def polyline(start: tuple[float, float], contour: list[Move]) -> list[tuple[float, float]]:
    """The contour as points (x diameter, z), its arcs as chords of at most ARC_STEP."""
    points = [start]
    for move in contour:
        if move.motion in (CW, CCW) and move.radius:
            points.extend(_arc_points(points[-1], move))
        else:
            points.append((move.x, move.z))
    return points


def _arc_points(begin: tuple[float, float], move: Move) -> list[tuple[float, float]]:
    """Chord points of an arc in the ZX plane, worked in radius coordinates (x/2)."""
    assert move.radius is not None
    (x0, z0), (x1, z1) = (begin[0] / 2, begin[1]), (move.x / 2, move.z)
    chord = math.hypot(x1 - x0, z1 - z0)
    r = abs(move.radius)
    if chord < EPS or chord > 2 * r + 1e-6:
        return [(move.x, move.z)]
    half = chord / 2
    height = math.sqrt(max(r * r - half * half, 0.0))
    # G2 turns clockwise seen from +Y; in the (z, x) plane of a lathe that is the sense below
    side = (-1 if move.motion == CW else 1) * (1 if move.radius > 0 else -1)
    mz, mx = (z0 + z1) / 2, (x0 + x1) / 2
    cz, cx = mz + side * height * -(x1 - x0) / chord, mx + side * height * (z1 - z0) / chord
    a0, a1 = math.atan2(x0 - cx, z0 - cz), math.atan2(x1 - cx, z1 - cz)
    sweep = a1 - a0
    clockwise = move.motion == CW
    if not clockwise and sweep < 0:
        sweep += 2 * math.pi
    if clockwise and sweep > 0:
        sweep -= 2 * math.pi
    steps = max(1, math.ceil(abs(sweep) / ARC_STEP))
    return [(2 * (cx + r * math.sin(a0 + sweep * i / steps)), cz + r * math.cos(a0 + sweep * i / steps))
            for i in range(1, steps + 1)]


def shifted(contour: list[Move], dx: float, dz: float) -> list[Move]:
    """The contour moved by (dx diameter, dz): the finish allowances U, W."""
    return [Move(m.motion, m.x + dx, m.z + dz, m.radius) for m in contour]


def rough(start: tuple[float, float], contour: list[Move], depth: float, retract: float,
          allowance: tuple[float, float], facing: bool = False) -> list[Move]:
    """G71 (facing False: passes along Z at falling diameters) or G72 (facing True: passes along X
    at successive Z): depth Δd and retract e as the control reads them (radius for G71), the
    allowances (U diameter, W); Fanuc type I (the contour goes away from the start monotonically)."""
    if depth <= 0:
        raise CycleError("the depth of cut must be above 0")
    offset = shifted(contour, *allowance)
    first = offset[0] if offset else None
    if first is None:
        raise CycleError("the cycle's contour has no blocks")
    # work in (a, b): a the axis stepped by the depth, b the axis cut along
    swap = _swapped if facing else _same
    step, lift = (depth, retract) if facing else (2 * depth, 2 * retract)
    back = 2 * retract if facing else retract
    a0, b0 = swap(*start)
    points = [swap(x, z) for x, z in polyline((first.x, first.z), offset[1:])]
    a_end = points[0][0]
    sense = math.copysign(1.0, a_end - a0)            # the way the levels go: into the stock
    if abs(a_end - a0) < EPS:
        raise CycleError("the contour starts at the start point's " + ("Z" if facing else "X"))
    motion = FEED if contour[0].motion == FEED else RAPID
    moves: list[Move] = []
    level = a0
    for _ in range(MAX_PASSES):
        level = level + sense * step
        if (level - a_end) * sense > 0:
            level = a_end
        b_end = _cut_end(points, level, -sense, b0)
        moves += _pass(swap, (level, b0, b_end), motion, (sense * -lift, math.copysign(back, b0 - b_end)))
        if abs(level - a_end) < EPS:
            break
    else:
        raise CycleError(f"more than {MAX_PASSES} passes")
    moves.append(Move(motion, *swap(a_end, b0)))
    moves += offset[1:]
    moves.append(Move(RAPID, *start))
    return moves


def _cut_end(points: list[tuple[float, float]], level: float, outward: float, b0: float) -> float:
    """Where a pass at `level` meets the contour: the first point of the contour beyond the level
    (towards the stock's outside), interpolated; the contour's end if it never goes beyond."""
    for (a1, b1), (a2, b2) in zip(points, points[1:]):
        if (a2 - level) * outward > 1e-9:
            if abs(a2 - a1) < EPS:
                return b1
            return b1 + (b2 - b1) * (level - a1) / (a2 - a1)
    return points[-1][1]


def _pass(swap: Swap, cut: tuple[float, float, float], motion: int, lift: tuple[float, float]) -> list[Move]:
    level, b0, b_end = cut
    return [Move(motion, *swap(level, b0)), Move(FEED, *swap(level, b_end)),
            Move(FEED, *swap(level + lift[0], b_end + lift[1])), Move(RAPID, *swap(level + lift[0], b0))]


def pattern(start: tuple[float, float], contour: list[Move], relief: tuple[float, float], passes: int,
            allowance: tuple[float, float]) -> list[Move]:
    """G73: the contour repeated `passes` times, from the relief (i radius, k) in to the allowances."""
    if passes < 1 or passes > MAX_PASSES:
        raise CycleError(f"the number of passes must be 1 … {MAX_PASSES}")
    moves: list[Move] = []
    for n in range(passes):
        share = (passes - 1 - n) / (passes - 1) if passes > 1 else 0.0
        dx, dz = allowance[0] + 2 * relief[0] * share, allowance[1] + relief[1] * share
        path = shifted(contour, dx, dz)
        moves += [Move(RAPID, path[0].x, path[0].z), *path[1:], Move(RAPID, *start)]
    return moves


def peck(start: tuple[float, float], end: tuple[float, float], steps: tuple[float, float], retract: float,
         grooving: bool) -> list[Move]:
    """G75 (grooving: pecks along X, stepping along Z) or G74 (pecks along Z, stepping along X):
    each peck Δ deep then back by the retract e, to the end, out at rapid, over by the step."""
    swap = _same if grooving else _swapped
    (a0, b0), (a1, b1) = swap(*start), swap(*end)
    peck_step, over = (steps[0], steps[1]) if grooving else (steps[1], steps[0])
    if peck_step <= 0 or (abs(b1 - b0) > EPS and over <= 0):
        raise CycleError("the peck depth and the step over must be above 0")
    moves: list[Move] = []
    b, sense_b = b0, math.copysign(1.0, b1 - b0)
    for _ in range(MAX_PASSES):
        moves += _pecks(swap, a0, a1, b, peck_step, retract)
        if abs(b - b1) < EPS:
            break
        b = b1 if abs(b1 - b) <= over else b + sense_b * over
        moves.append(Move(RAPID, *swap(a0, b)))
    moves.append(Move(RAPID, *start))
    return moves


def _pecks(swap: Swap, a0: float, a1: float, b: float, step: float, retract: float) -> list[Move]:
    sense = math.copysign(1.0, a1 - a0)
    moves: list[Move] = []
    a = a0
    for _ in range(MAX_PASSES):
        a = a1 if abs(a1 - a) <= step else a + sense * step
        moves.append(Move(FEED, *swap(a, b)))
        if abs(a - a1) < EPS:
            break
        moves.append(Move(RAPID, *swap(a - sense * retract, b)))
    moves.append(Move(RAPID, *swap(a0, b)))
    return moves


class Thread(msgspec.Struct, frozen=True):
    """G76's words as the control reads them, in mm: the end (X root diameter, Z), the height k
    and first depth Δd (radius), the minimum cut Δdmin, the finish allowance d, the finish passes
    m, the tool angle a (degrees), the lead L (mm/rev) and the taper i (radius, start minus end)."""
    x: float
    z: float
    height: float
    first: float
    lead: float
    minimum: float = 0.0
    allowance: float = 0.0
    finish_passes: int = 1
    angle: float = 60.0
    taper: float = 0.0


def thread_depths(thread: Thread) -> list[float]:
    """The depth (radius) of each pass: Δd·√n while below k − d, each at least Δdmin deeper than
    the one before, then k − d, then the m finish passes at k."""
    if thread.height <= 0 or thread.first <= 0:
        raise CycleError("the thread height and the first depth must be above 0")
    rough_to = thread.height - thread.allowance
    depths: list[float] = []
    for n in range(1, MAX_PASSES):
        depth = thread.first * math.sqrt(n)
        if depths and depth - depths[-1] < thread.minimum:
            depth = depths[-1] + thread.minimum
        if depth >= rough_to - EPS:
            break
        depths.append(depth)
    else:
        raise CycleError(f"more than {MAX_PASSES} thread passes")
    return [*depths, rough_to, *([thread.height] * max(thread.finish_passes, 1))]


def threading(start: tuple[float, float], thread: Thread) -> list[Move]:
    """G76: each pass rapids in to its depth, shifted along the flank by depth·tan(a/2), cuts to
    the end Z (G32 at the lead), rapids out to the start X and back to the start Z."""
    x0, z0 = start
    outward = math.copysign(1.0, x0 - thread.x)        # an outside thread: the start lies above the root
    sense_z = math.copysign(1.0, thread.z - z0)
    flank = math.tan(math.radians(thread.angle / 2))
    moves: list[Move] = []
    for depth in thread_depths(thread):
        x = thread.x + outward * 2 * (thread.height - depth)
        shift = -sense_z * depth * flank
        x_start = x + 2 * thread.taper
        moves += [Move(RAPID, x0, z0 + shift), Move(RAPID, x_start, z0 + shift),
                  Move(THREAD, x, thread.z), Move(RAPID, x0, thread.z), Move(RAPID, x0, z0)]
    return moves
