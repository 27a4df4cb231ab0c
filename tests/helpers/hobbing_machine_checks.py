"""Checks of issue 14 that need the machine record: the fixture and tailstock the hob must never
touch, the table speed the coupling demands (helical or tangential term included, at G0 too), and
the cycle time the header states (the BRIEF's model, recomputed from the program text).
"""
from __future__ import annotations

import math
import re

from helpers.hobbing_checks import (
    Case,
    approach_problems,
    contract_problems,
    coupling_problems,
    depth_problems,
    din_move,
    envelope_problems,
    feed_problems,
)
from helpers.hobbing_envelope import Solid, hob_depths, known_xz, shift_limits
from helpers.hobbing_reference import Nc, swivel

ROUND = 0.002
REACH = 1000.0      # mm: the fixture and tailstock are long cylinders along the work axis


def obstacles(case: Case) -> list[tuple[str, float, Solid]]:
    """Fixture below the lowest unit, tailstock above the top face (when the job clamps with it),
    as (name, diameter, cylinder) in the DIN frame, from the machine record; with a job's
    work-holding, its part under the gear and its centre (the work_holding record)."""
    found = []
    bottom = min(u.bottom for u in case.gear.units)
    top = max(u.z_top for u in case.gear.units)
    diameter, gap = case.machine.fixture
    if case.holding is not None:    # the job's work-holding under the gear, on the machine's fixture
        found.append(("work-holding", case.holding.diameter,
                      Solid(case.holding.diameter / 2, bottom - gap - case.holding.height, bottom - gap)))
        bottom -= case.holding.height
    if diameter > 0:
        found.append(("fixture", diameter, Solid(diameter / 2, bottom - gap - REACH, bottom - gap)))
    diameter, gap = case.machine.tailstock
    if case.holding is not None:    # its centre in place of the machine's tailstock
        diameter = case.holding.tailstock_diameter
    if diameter > 0 and case.job.tailstock:
        found.append(("tailstock", diameter, Solid(diameter / 2, top + gap, top + gap + REACH)))
    return found


def obstacle_problems(nc: Nc, case: Case) -> list[str]:
    """No move brings the hob (3-D: tip cylinder, length, swivel, shift) into the fixture or the tailstock."""
    pairs = [(move, body) for move in (din_move(m, case.machine) for m in nc.moves) if known_xz(move)
             for body in obstacles(case)]
    depths = hob_depths([(move, solid) for move, (_, _, solid) in pairs], swivel(case.gear, case.hob), case.hob.r0,
                        case.hob.length, shift_limits(nc, case.machine))
    return [f"{move.mode} block {move.block} {nc.blocks[move.block].text!r}: hob {depth:.3f} mm "
            f"into the {name} (Ø{diameter:g})" for (move, (name, diameter, _)), depth in zip(pairs, depths)
            if depth > ROUND]


def _coupling_at(nc: Nc) -> dict[int, tuple | None]:
    """Block index → the EGON arguments in force (None when decoupled)."""
    state, found = None, {}
    for block in nc.blocks:
        if "EGON" in block.calls:
            state = block.calls["EGON"]
        if "EGOFS" in block.calls or "EGDEL" in block.calls:
            state = None
        found[block.index] = state
    return found


def _spindle_at(nc: Nc) -> dict[int, float]:
    running, found = 0.0, {}
    for block in nc.blocks:
        if 3 in block.m or 4 in block.m:
            running = float(block.words.get("S", running or 0.0))
        if 5 in block.m:
            running = 0.0
        found[block.index] = running
    return found


def table_speed_problems(nc: Nc, case: Case) -> list[str]:
    """n_C = |k_B·S + (k_Z·v_Z + k_Y·v_Y)/360| ≤ the machine's table speed, for every coupled move
    (G0 at the rapid rate along its longest axis)."""
    coupling, spindle = _coupling_at(nc), _spindle_at(nc)
    problems = []
    for move in nc.moves:
        args = coupling.get(move.block)
        if not args or len(args) < 5 or not isinstance(move.start["X"], float):
            continue
        speeds = _axis_speeds(move, case)
        turn = float(args[3]) / float(args[4]) * spindle[move.block]
        for k in range(5, len(args) - 2, 3):
            turn += float(args[k + 1]) / float(args[k + 2]) * speeds.get(args[k], 0.0) / 360
        if abs(turn) > case.machine.table_speed_max * 1.005:
            problems.append(f"{move.mode} block {move.block} {nc.blocks[move.block].text!r}: the table turns at "
                            f"{abs(turn):.1f} r/min, above {case.machine.table_speed_max:g}")
    return problems


def _axis_speeds(move, case: Case) -> dict[str, float]:
    deltas = {a: move.delta(a) for a in "XYZ"}
    if move.mode == "G0":
        longest = max(abs(d) for d in deltas.values())
        return {a: case.machine.rapid_rate * d / longest for a, d in deltas.items()} if longest else {}
    length = math.sqrt(sum(d * d for d in deltas.values()))
    return {a: move.feed * d / length for a, d in deltas.items()} if length else {}


def cycle_time(nc: Nc, case: Case) -> float:
    """The BRIEF's model, minutes: G1 path/F, G0 longest axis/rapid rate, G4 F seconds; moves from
    an unknown position count 0."""
    minutes = 0.0
    for move in nc.moves:
        deltas = [move.delta(a) for a in "XYZ"]
        if move.mode == "G1" and move.feed:
            minutes += math.sqrt(sum(d * d for d in deltas)) / move.feed
        elif move.mode == "G0":
            minutes += max(abs(d) for d in deltas) / case.machine.rapid_rate
    dwell = sum(float(b.words.get("F", 0.0)) for b in nc.blocks if 4 in b.g)
    return minutes + dwell / 60


CYCLE_TIME = re.compile(r"^; CYCLE TIME (\d+\.\d) MIN$")


def cycle_time_problems(nc: Nc, case: Case, tolerance: float = 0.1) -> list[str]:
    """The header states `; CYCLE TIME <min, 1 decimal> MIN` and agrees with the program's own
    moves (tolerance: the rounding plus the first rapid from an unknown position)."""
    stated = [float(m[1]) for m in map(CYCLE_TIME.match, nc.lines) if m]
    expected = cycle_time(nc, case)
    if len(stated) != 1:
        return [f"expected one '; CYCLE TIME <minutes> MIN' header line, found {len(stated)} (model: {expected:.1f})"]
    if abs(stated[0] - expected) > tolerance:
        return [f"header says {stated[0]} min, the program's moves take {expected:.2f} min"]
    return []


ALL_CHECKS = (contract_problems, coupling_problems, depth_problems, approach_problems, feed_problems,
              envelope_problems, obstacle_problems, table_speed_problems, cycle_time_problems)


def all_problems(nc: Nc, case: Case) -> list[str]:
    """Every check of issue 14, each finding prefixed with its check's name."""
    return [f"{check.__name__}: {p}" for check in ALL_CHECKS for p in check(nc, case)]
