"""The acceptance checks of issue 14 on a program read by tests/helpers/hobbing_reference.py.

Each `*_problems(nc, case)` returns one-line findings (empty = the program agrees with design notes
§7 and the reference). `Case` holds what the test knows independently of the engine: the gear
(its units in the DIN frame), the hob, the machine's senses and the job's choices.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

from helpers.hobbing_envelope import Solid, Sweep, hob_depths, intrusions, known_xz, shift_limits
from helpers.hobbing_reference import (
    Gear,
    Hob,
    Machine,
    Move,
    Nc,
    Unit,
    approach_needed,
    b_ratio,
    full_depth,
    lead_angle,
    root_solid,
    roughing_feed_max,
    swivel,
    taper_depth,
    tip_radius_at,
    unit_solid,
    y_factor,
    z_factor,
)

ROUND = 0.002        # mm or degrees: coordinates and angles are written with 3 decimals
DEPTH = 0.01         # mm, last cut against (d_f2 + d_a0)/2 (Contract), and below the root at most
AXIAL_CLASSES = ("spur", "helical", "taper", "crowned", "duplex")


@dataclass(frozen=True)
class Job:
    coolant: bool = True
    shift: float | str = 0.0          # fixed shift position (DIN), or 'per part'
    worm_feed: str = "radial"
    tailstock: bool = True


@dataclass(frozen=True)
class Holding:
    """A job's work-holding as the shop's record declares it (table work_holding, issue 29): its
    part under the gear (diameter, height, on the machine's fixture) and its centre above (Ø, 0 = none)."""
    diameter: float
    height: float
    tailstock_diameter: float


@dataclass(frozen=True)
class Case:
    gear: Gear
    hob: Hob
    machine: Machine = Machine()
    job: Job = Job()
    holding: Holding | None = None    # the program's `; FIXTURE <id>`; None: the machine's own

    @property
    def tangential(self) -> bool:
        return self.gear.gear_class == "worm_wheel" and self.job.worm_feed == "tangential"


@dataclass
class Cut:
    moves: list[Move]          # the G1 moves, in DIN coordinates
    retract: Move | None
    unit: Unit


def din_move(move: Move, machine: Machine) -> Move:
    convert = lambda pos: {a: machine.din(a, v) for a, v in pos.items()}   # noqa: E731
    return Move(move.block, move.mode, convert(move.start), convert(move.end), move.feed, move.speed)


def cuts(nc: Nc, case: Case) -> list[Cut]:
    """Runs of consecutive G1 moves (a G0 ends a run), each with its retract and the unit it cuts:
    the one whose teeth the coupling in force is set for (by Z overlap when that is ambiguous)."""
    found, run = [], []
    moves = [din_move(m, case.machine) for m in nc.moves]
    for move in moves:
        if move.mode == "G1":
            run.append(move)
            continue
        if run:
            found.append(Cut(run, move, _unit_of(nc, case, run)))
            run = []
    if run:
        found.append(Cut(run, None, _unit_of(nc, case, run)))
    return found


def _unit_of(nc: Nc, case: Case, run: list[Move]) -> Unit:
    couplings = [args for index, args in nc.calls("EGON") if index < run[0].block]
    teeth = couplings[-1][4] if couplings and len(couplings[-1]) > 4 else None
    matching = [u for u in case.gear.units if str(u.z2) == teeth]
    if len(matching) == 1:
        return matching[0]
    zs = [z for m in run for z in (m.start["Z"], m.end["Z"]) if isinstance(z, float)]
    span = (min(zs), max(zs)) if zs else (0.0, 0.0)
    return max(case.gear.units, key=lambda u: min(span[1], u.z_top) - max(span[0], u.bottom))


def passes(cut: Cut) -> list[Move]:
    return [m for m in cut.moves if m.delta("Z") != 0]


# ---------------------------------------------------------------- §7 program contract

def contract_problems(nc: Nc, case: Case) -> list[str]:
    problems = []
    if not re.fullmatch(r"%_N_[A-Z_][A-Z0-9_]*_MPF", nc.lines[0] if nc.lines else ""):
        problems.append(f"first line {nc.lines[:1]} is not %_N_<NAME>_MPF")
    if nc.lines[1:2] != [";$PATH=/_N_MPF_DIR"]:
        problems.append(f"second line {nc.lines[1:2]} is not ;$PATH=/_N_MPF_DIR")
    motion = nc.first("motion")
    if motion is None:
        return problems + ["no motion at all"]
    for token in ("G90", "G71", "G94", "WALIMON", case.machine.work_offset):
        if (nc.first(token) is None) or nc.first(token) > motion:
            problems.append(f"{token} not programmed before the first motion {nc.blocks[motion].text!r}")
    problems += _limit_problems(nc, motion)
    return problems + _coupling_order_problems(nc, case) + _spindle_problems(nc, case)


def _limit_problems(nc: Nc, motion: int) -> list[str]:
    lower = [b for b in nc.blocks if 25 in b.g and {"X", "Y", "Z"} <= set(b.axes)]
    upper = [b for b in nc.blocks if 26 in b.g and {"X", "Y", "Z"} <= set(b.axes)]
    if not lower or not upper or lower[0].index > motion or upper[0].index > motion:
        return ["no G25 X Y Z and G26 X Y Z before the first motion"]
    low, high = lower[0].axes, upper[0].axes
    return [f"{nc.blocks[m.block].text!r}: {axis}{value} outside G25/G26 {low[axis]} … {high[axis]}"
            for m in nc.moves for axis, value in nc.blocks[m.block].axes.items()
            if axis in "XYZ" and isinstance(value, float) and not low[axis] <= value <= high[axis]]


def _coupling_order_problems(nc: Nc, case: Case) -> list[str]:
    problems = []
    egon, egdef = nc.first("EGON"), nc.first("EGDEF")
    if egon is None or egdef is None:
        return ["no EGDEF/EGON"]
    defined = False
    for block in nc.blocks:
        if "EGDEF" in block.calls and defined:
            problems.append(f"{block.text!r}: EGDEF while a coupling of C still exists (EGDEL first, §A7)")
        defined = (defined or "EGDEF" in block.calls) and "EGDEL" not in block.calls
    swivels = [b.index for b in nc.blocks if "A" in b.equals and b.index < egdef]
    if not swivels:
        problems.append("no A=… before EGDEF")
    y = nc.after[egon - 1]["Y"] if egon else None
    expected = case.job.shift
    if y is None:
        problems.append("Y never positioned before EGON")
    elif not case.tangential and isinstance(expected, float) and \
            (not isinstance(y, float) or abs(case.machine.din("Y", y) - expected) > ROUND):
        problems.append(f"Y before EGON is {y}, expected the shift position {expected:g} (DIN)")
    if not case.tangential and expected == "per part" and not isinstance(y, str):
        problems.append(f"Y before EGON is {y}, expected the part counter's shift parameter")
    return problems


def _spindle_problems(nc: Nc, case: Case) -> list[str]:
    problems = []
    first_g1, last_g1 = nc.first("G1 move"), nc.last("G1 move")
    if first_g1 is None:
        return ["no G1"]
    m3 = nc.first("M3")
    if m3 is None or m3 > first_g1 or "S" not in nc.blocks[m3].words:
        problems.append("no M3 with S before the first G1")
    if case.job.coolant:
        if nc.first("M8") is None or nc.first("M8") > first_g1:
            problems.append("no M8 before the first G1")
        if nc.last("M9") is None or nc.last("M9") < last_g1:
            problems.append("no M9 after the last G1")
    elif nc.where("M8") or nc.where("M9"):
        problems.append("M8/M9 although coolant is off")
    off, delete, stop = nc.last("EGOFS"), nc.last("EGDEL"), nc.last("M5")
    for name, index in (("EGOFS(C)", off), ("EGDEL(C)", delete), ("M5", stop)):
        if index is None or index < last_g1:
            problems.append(f"no {name} after the last cut")
    if off is not None and delete is not None and delete < off:
        problems.append("EGDEL before EGOFS")
    if not nc.blocks or 30 not in nc.blocks[-1].m:
        problems.append("the last block is not M30")
    return problems


# ---------------------------------------------------------------- §A5/§A7 coupling values

def coupling_problems(nc: Nc, case: Case) -> list[str]:
    gear = case.gear
    problems = []
    egons = nc.calls("EGON")
    if not egons:
        return ["no EGON"]
    lead = "Y" if case.tangential else "Z" if gear.beta and gear.gear_class != "worm_wheel" else None
    for _, args in nc.calls("EGDEF"):
        wanted = ("C", "B", "1") + ((lead, "1") if lead else ())
        if args != wanted:
            problems.append(f"EGDEF{args} expected EGDEF{wanted}")
    teeth = {u.z2 for u in gear.units}
    for _, args in egons:
        problems += _egon_problems(args, case, lead, teeth)
    coupled = {args[4] for _, args in egons if len(args) > 4}
    problems += [f"no EGON with denominator z2 = {z2} for unit z{z2}" for z2 in sorted(teeth) if str(z2) not in coupled]
    problems += _swivel_problems(nc, case)
    return problems


def _egon_problems(args: tuple, case: Case, lead: str | None, teeth: set) -> list[str]:
    text = f"EGON({','.join(args)})"
    if len(args) < 5 or args[:3] != ("C", "FINE", "B") or not re.fullmatch(r"[+-]?\d+", args[3]) \
            or not re.fullmatch(r"\d+", args[4]):
        return [f"{text}: expected EGON(C,\"FINE\",B,<int>,<int>…)"]
    z2 = int(args[4])
    if z2 not in teeth:
        return [f"{text}: denominator {z2} is no unit's tooth count {sorted(teeth)}"]
    problems = []
    expected = b_ratio(case.hob, z2, case.machine)
    if (int(args[3]), z2) != expected:
        problems.append(f"{text}: B ratio {args[3]}:{z2}, expected {expected[0]}:{expected[1]} "
                        f"(-h_hob·z0·c·b, hob {case.hob.hand} z0={case.hob.z0})")
    if lead is None:
        return problems + ([f"{text}: no second leading axis expected"] if len(args) != 5 else [])
    factor = z_factor(case.gear, z2, case.machine) if lead == "Z" else y_factor(case.gear, case.hob, case.machine)
    if len(args) != 8 or args[5] != lead or args[7] != "1" or not re.fullmatch(r"-?\d+\.\d{6}", args[6]):
        return problems + [f"{text}: expected {lead},<factor with 6 decimals>,1 (factor {factor:.6f})"]
    if abs(float(args[6]) - factor) > 5.1e-7:
        problems.append(f"{text}: {lead} factor {args[6]}, expected {factor:.6f}")
    return problems


def _swivel_problems(nc: Nc, case: Case) -> list[str]:
    egon = nc.first("EGON")
    blocks = [b for b in nc.blocks if "A" in b.words and b.index < egon]
    if not blocks:
        return ["no swivel A before EGON"]
    written = blocks[-1]
    value = written.words["A"]
    expected = swivel(case.gear, case.hob)
    if not re.search(r"A=-?\d+\.\d{3}\b", written.text):
        return [f"{written.text!r}: A not written A=<3 decimals>"]
    if abs(case.machine.din("A", value) - expected) > ROUND:
        return [f"{written.text!r}: A={value}, expected {expected * case.machine.a:.3f} "
                f"(h_hob·γ − h_gear·β = {expected:.3f} in DIN, γ = {lead_angle(case.gear.mn, case.hob):.3f})"]
    return []


# ---------------------------------------------------------------- geometry of the cuts

def _x_at(moves: list[Move], z: float) -> float | None:
    for move in moves:
        z0, z1 = move.start["Z"], move.end["Z"]
        if min(z0, z1) - 1e-9 <= z <= max(z0, z1) + 1e-9 and z0 != z1:
            return move.start["X"] + (z - z0) * (move.end["X"] - move.start["X"]) / (z1 - z0)
    return None


def depth_problems(nc: Nc, case: Case) -> list[str]:
    """The last cut of each unit reaches full depth: (d_f2 + d_a0)/2 (§B3) at mid-face, crowned at
    mid-face, worm wheels at the plunge/Y pass; a taper at the top face (where the stated diameters
    hold) where the hob's tip section touches the root line (`taper_depth`), and no taper pass takes
    the hob (3-D) more than DEPTH below the root cone."""
    problems, all_cuts = [], cuts(nc, case)
    taper = case.gear.gear_class == "taper"
    for unit in case.gear.units:
        mine = [c for c in all_cuts if c.unit == unit]
        if not mine:
            problems.append(f"unit z{unit.z2}: no cut")
            continue
        if taper:
            problems += _taper_depth_problems(nc, mine[-1], case)
            continue
        reached = _depth_of(mine[-1], case)
        expected = full_depth(unit, case.hob)
        rule = "the tip section touching the root line" if taper else "full depth (d_f2 + d_a0)/2"
        if reached is None:
            problems.append(f"unit z{unit.z2}: the last cut's pass does not cross Z{_depth_z(unit, case):g} (DIN) "
                            f"where its depth is measured")
        elif abs(reached - expected) > DEPTH:
            problems.append(f"unit z{unit.z2}: last cut at X{reached:.3f}, {rule} = {expected:.3f}")
    return problems + _cone_problems(all_cuts, case) + (_root_problems(nc, all_cuts, case) if taper else [])


def _taper_depth_problems(nc: Nc, last: Cut, case: Case) -> list[str]:
    """A taper's last cut touches the root cone (3-D): the deepest point of the hob over its pass
    lies within DEPTH of the cone (deeper is `_root_problems`). The tip section in the plane
    Y = 0 (`taper_depth`) is the first guess; a swivelled hob's points off that plane reach
    further along Z (§B7), so the section alone can leave the hob a little short of the cone."""
    pairs = [(move, root_solid(case.gear, last.unit)) for move in passes(last)]
    depths = _deepest(pairs, case, shift_limits(nc, case.machine))
    deepest = max(depths, default=None)
    if deepest is None or deepest >= -DEPTH:
        return []
    section = taper_depth(case.gear, last.unit, case.hob)
    return [f"unit z{last.unit.z2}: the last cut stays {-deepest:.3f} mm above the root cone (3-D); "
            f"the tip section touching the root line would be at X{section:.3f}"]


def _root_problems(nc: Nc, all_cuts: list[Cut], case: Case) -> list[str]:
    pairs = [(move, cut.unit) for cut in all_cuts for move in passes(cut)]
    depths = _deepest([(move, root_solid(case.gear, unit)) for move, unit in pairs], case,
                      shift_limits(nc, case.machine))
    return [f"pass block {move.block}: the hob (3-D) reaches {depth:.3f} mm below unit z{unit.z2}'s root cone"
            for (move, unit), depth in zip(pairs, depths) if depth > DEPTH]


def _depth_of(cut: Cut, case: Case) -> float | None:
    if case.gear.gear_class == "worm_wheel":
        return min(m.end["X"] for m in cut.moves)
    return _x_at(passes(cut), _depth_z(cut.unit, case))


def _depth_z(unit: Unit, case: Case) -> float:
    return unit.z_top if case.gear.gear_class == "taper" else (unit.z_top + unit.bottom) / 2


def _cone_problems(all_cuts: list[Cut], case: Case) -> list[str]:
    """A taper's last pass (issue 29) holds the hob's whole tip cylinder tangent to the root cone,
    continued beyond the faces: at every vertex of its moves in X and Z the standing hob (3-D,
    unshifted) reaches the cone within DEPTH, neither short of it nor into it (beyond a face the
    pass may hold X and move along Z only, above the cone: `_root_problems` checks those). For a
    swivelled hob these centres are not on the straight line X(0) + Z·tanδ (§B12): a polyline."""
    if case.gear.gear_class != "taper":
        return []
    found = []
    for unit in case.gear.units:
        mine = [c for c in all_cuts if c.unit == unit]
        cone = root_solid(case.gear, unit)
        endless = Solid(cone.radius, -1e4, 1e4, cone.slope, cone.z_ref)   # the cone continued past the faces
        moves = [m for m in passes(mine[-1]) if m.delta("X") != 0] if mine else []   # not the held X's
        points = [(m.end["X"], m.end["Z"]) for m in moves] + [(m.start["X"], m.start["Z"]) for m in moves[:1]]
        sweeps = [Sweep(x, z, x, z, swivel(case.gear, case.hob)) for x, z in points]
        depths = intrusions(sweeps, [endless] * len(sweeps), case.hob.r0, case.hob.length) if sweeps else []
        found += [f"pass vertex X{x:.3f} Z{z:.3f}: the hob (3-D) reaches {depth:+.3f} mm into the root cone, "
                  f"not tangent to it (±{DEPTH:g})" for (x, z), depth in zip(points, depths) if abs(depth) > DEPTH]
    return found


def approach_problems(nc: Nc, case: Case) -> list[str]:
    """Infeed clear of the blank at the approach Z; the pass ends with the hob centre beyond the
    other face (axial classes); the tangential hob starts and ends clear of the wheel."""
    if case.gear.gear_class == "worm_wheel":
        return _worm_clear_problems(nc, case)
    problems = []
    eta = swivel(case.gear, case.hob)
    for cut in cuts(nc, case):
        infeed, over = cut.moves[0], passes(cut)
        if infeed.delta("Z") != 0 or not over:
            problems.append(f"block {infeed.block}: a cut must start with a radial infeed, then an axial pass")
            continue
        problems += _infeed_problems(cut, infeed, over, case, eta, shift_limits(nc, case.machine))
    return problems


def _infeed_problems(cut: Cut, infeed: Move, over: list[Move], case: Case, eta: float, limits: tuple) -> list[str]:
    unit, hob, gear = cut.unit, case.hob, case.gear
    down = over[-1].end["Z"] < infeed.end["Z"]
    face, far = (unit.z_top, unit.bottom) if down else (unit.bottom, unit.z_top)
    x, z = infeed.end["X"], infeed.end["Z"]
    h = tip_radius_at(gear, unit, face) + hob.r0 - x
    problems = []
    if gear.beta == 0:
        depth = _deepest([(Move(infeed.block, "G0", infeed.end, infeed.end, None, None), unit_solid(gear, unit))],
                        case, limits)[0]
        if depth > ROUND:
            problems.append(f"infeed block {infeed.block} to X{x} at Z{z} (h = {h:.3f}): the hob is "
                            f"{depth:.3f} mm inside the blank (unit z{unit.z2})")
    else:
        needed = approach_needed(h, hob, eta, unit.da)
        distance = (z - face) if down else (face - z)
        if distance < needed - ROUND:
            problems.append(f"infeed block {infeed.block} to X{x} at Z{z} (h = {h:.3f}): {distance:.3f} mm from "
                            f"the face Z{face:g}, §B7 needs {needed:.3f}")
    end = over[-1].end["Z"]
    if (down and not end < far) or (not down and not end > far):
        problems.append(f"pass block {over[-1].block} ends at Z{end}, not beyond the other face Z{far:g}")
    return problems


def _worm_clear_problems(nc: Nc, case: Case) -> list[str]:
    hob, unit = case.hob, case.gear.first
    problems = []
    for cut in cuts(nc, case):
        start = cut.moves[0]
        if not case.tangential:
            if start.start["X"] < (unit.da + hob.da0) / 2 - ROUND:
                problems.append(f"plunge block {start.block} starts at X{start.start['X']}, inside tip contact")
            continue
        for move in (start, cut.moves[-1]):
            for pos in ((move.start, move.end) if move is start else (move.end,)):
                near_x = max(pos["X"] - hob.r0, 0.0)
                near_y = max(abs(pos["Y"]) - hob.length / 2, 0.0) if isinstance(pos["Y"], float) else 0.0
                if math.hypot(near_x, near_y) < unit.da / 2 - ROUND:
                    problems.append(f"block {move.block}: hob at X{pos['X']} Y{pos['Y']} inside the wheel's tip "
                                    f"cylinder d_a {unit.da}")
    return problems


def feed_problems(nc: Nc, case: Case) -> list[str]:
    """§C: every rough or single pass feeds at most the roughing maximum for the module, per
    workpiece revolution (n2 = S·z0/z2, axial component of a slanted path)."""
    if case.gear.gear_class not in AXIAL_CLASSES:
        return []
    limit = roughing_feed_max(case.gear.mn)
    problems, all_cuts = [], cuts(nc, case)
    for unit in case.gear.units:
        mine = [c for c in all_cuts if c.unit == unit]
        for cut in (mine[:-1] if len(mine) > 1 else mine):
            per_rev, block = max((_axial_per_rev(move, case.hob, unit), move.block) for move in passes(cut))
            if per_rev > limit + 0.005:
                problems.append(f"unit z{unit.z2} pass block {block}: {per_rev:.2f} mm per workpiece "
                                f"revolution, §C roughing maximum for m{case.gear.mn:g} is {limit:.2f}")
    return problems


def _axial_per_rev(move: Move, hob: Hob, unit: Unit) -> float:
    """§B5: f_a = axial feed / n2, n2 = n0·z0/z2; a slanted path's axial part is F·|ΔZ|/length."""
    length = math.hypot(move.delta("X"), move.delta("Y"), move.delta("Z"))
    table = (move.speed or 0) * hob.z0 / unit.z2
    return move.feed * abs(move.delta("Z")) / length / table if table else math.inf


def envelope_problems(nc: Nc, case: Case) -> list[str]:
    """No move brings the hob (3-D: tip cylinder, length, swivel, shift) into a unit other than the
    one being cut during its cut; outside the cuts into none."""
    if case.gear.gear_class == "worm_wheel":
        return []
    during = {}
    for cut in cuts(nc, case):
        for move in cut.moves + ([cut.retract] if cut.retract else []):
            during[move.block] = cut.unit
    pairs = [(move, unit) for move in (din_move(m, case.machine) for m in nc.moves) if known_xz(move)
             for unit in case.gear.units if during.get(move.block) != unit]
    depths = _deepest([(move, unit_solid(case.gear, unit)) for move, unit in pairs], case,
                     shift_limits(nc, case.machine))
    return [f"{move.mode} block {move.block} {nc.blocks[move.block].text!r}: hob {depth:.3f} mm "
            f"into unit z{unit.z2} (d_a {unit.da}, Z{unit.bottom:g}…{unit.z_top:g})"
            for (move, unit), depth in zip(pairs, depths) if depth > ROUND]


def _deepest(pairs: list, case: Case, limits: tuple) -> list[float]:
    return hob_depths(pairs, swivel(case.gear, case.hob), case.hob.r0, case.hob.length, limits)
