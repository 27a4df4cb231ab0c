"""Feeds and cutting speeds of every cut against the tool and material table
(engine.machines.turning_cutting, by operation kind, tool material and workpiece material):
the feed per revolution f = F/S under G94/G98 (mm/min), F under G95/G99, a thread's lead;
the cutting speed vc = π·D·S/1000 m/min with D the largest diameter the cut reaches (G97), or
S itself under G96 (constant cutting speed). A thread pass's lead (ISO G32 F, 840D G33 K or F,
mm/rev) must be the drawn pitch (module_params.cutmotion:n.thread_pitch) within
LEAD_TOLERANCE_MM: another lead cuts another helix than the drawing's. One finding per operation
and reason: a table value broken once is broken on every pass of the operation."""
from __future__ import annotations

import math

from ...errors import EngineError
from ...machines.turning_cutting import job_materials, turning_cut_problem
from .follow import THREAD, Move
from .report import TurningReport
from .work import FIX, TurningRecords

LEAD_TOLERANCE_MM = 1e-4     # the programs write the lead to 0.0001 mm (ISO F{pitch:.4f})


def check_cutting(moves: list[Move], records: TurningRecords, params: dict, module_params: dict,
                  report: TurningReport) -> None:
    said: set[tuple[int, str]] = set()
    for move in moves:
        op = records.operations.get(move.operation) if move.operation else None
        if move.kind == "rapid" or op is None:
            continue
        vc, f = cutting_speed(move), feed_per_revolution(move)
        tool_material, workpiece_material = job_materials(params, module_params, op.number)
        problem = turning_cut_problem(op.kind, tool_material, workpiece_material, vc, f)
        if move.kind == THREAD and op.kind == "THREAD":
            problem = lead_problem(move, thread_pitch(module_params, op.number)) or problem
        if problem and (op.number, problem) not in said:
            said.add((op.number, problem))
            report.add(move.number, move.line, f"operation {op.number} {op.kind}: vc {vc:.0f} m/min, "
                       f"f {f:.3f} mm/rev: {problem}")


def thread_pitch(module_params: dict, n: int) -> float:
    """The drawn thread's pitch, mm (module_params.cutmotion:n.thread_pitch)."""
    pitch = (module_params.get(f"cutmotion:{n}") or {}).get("thread_pitch")
    if isinstance(pitch, bool) or not isinstance(pitch, (int, float)) or not 0 < pitch < math.inf:
        raise EngineError(f"module_params.cutmotion:{n}.thread_pitch = {pitch!r} must be a positive number "
                          f"(the THREAD operation's pitch, mm); {FIX}")
    return float(pitch)


def lead_problem(move: Move, pitch: float) -> str | None:
    if move.lead is None:
        return f"a thread pass without its lead (F or K), the drawn pitch is {pitch:.4f} mm"
    if abs(move.lead - pitch) > LEAD_TOLERANCE_MM:
        return f"thread lead {move.lead:.4f} mm, the drawn pitch {pitch:.4f} mm: it cuts another helix"
    return None


def cutting_speed(move: Move) -> float:
    """m/min at the largest diameter of the cut."""
    speed = move.speed or 0.0
    if move.constant_speed:
        return speed
    diameter = 2.0 * max(r for _, r in move.points)
    return math.pi * diameter * speed / 1000.0


def feed_per_revolution(move: Move) -> float:
    """mm per spindle revolution (math.inf with the spindle at S0: no revolution to feed by)."""
    if move.kind == THREAD:
        return move.lead or 0.0
    feed = move.feed or 0.0
    if not move.per_minute:
        return feed
    rpm = _rpm(move)
    return feed / rpm if rpm > 0 else math.inf


def _rpm(move: Move) -> float:
    speed = move.speed or 0.0
    if not move.constant_speed:
        return speed
    diameter = 2.0 * max(r for _, r in move.points)
    return speed * 1000.0 / (math.pi * diameter) if diameter > 0 else math.inf
