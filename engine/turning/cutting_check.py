"""The planner's early warning on cutting data (reference §E1): every present operation's
spindle speed and feed, at the largest diameter its passes cut at, must lie in the turning
cutting-data table (engine.machines.turning_cutting) for the job's tool and workpiece
materials. The proof is the turning simulation, which reads the same table from the program
text; this check refuses a runner's edit (a feed of 19,999 mm/min, S3999) before anything is
rendered, with the same one-line reason."""
from __future__ import annotations

import math

from ..errors import EngineError
from ..machines.turning_cutting import job_materials, turning_cut_problem
from .moves import Pass

# Where the value comes from: the drawing's @-codes on its layer (or import-dxf's options) before a
# job exists, the job's module_params after.
CUTTING_FIX = ("importing, change @S/@F on the drawing's layer {n} (or --speed, --feed, --material, --tool-material); "
               "for a stored job, job.module_params in SQL, then instantiate the job again; nothing stored")
CUTTING_KINDS = ("feed", "cw", "ccw", "thread")   # Move.kind of the moves that cut (a rapid does not)


def check_cutting_data(params: dict, module_params: dict, passes: dict[int, list[Pass]]) -> None:
    """Each operation's vc (at its largest cutting diameter) and f = F/S against the table."""
    for n, found in passes.items():
        diameters = [abs(move.x) for one in found for move in one if move.kind in CUTTING_KINDS]
        if diameters:
            check_operation_cut(params, module_params, n, max(diameters))


def check_operation_cut(params: dict, module_params: dict, n: int, diameter: float) -> None:
    cutmotion, rpm = module_params[f"cutmotion:{n}"], module_params[f"cutcond:{n}"]["spindle_rpm"]
    kind = cutmotion["kind"]
    tool, workpiece = job_materials(params, module_params, n)
    vc = math.pi * diameter * rpm / 1000.0
    feed = cutmotion.get("thread_pitch") if kind == "THREAD" else cutmotion["feed"] / rpm
    problem = turning_cut_problem(kind, tool, workpiece, vc, feed)
    if problem:
        said = f"S{rpm:g} at Ø{diameter:.4g}" + ("" if kind == "THREAD" else f", F{cutmotion['feed']:g} mm/min")
        raise EngineError(f"operation {n} ({kind}, module_params.cutcond:{n} / cutmotion:{n}): {said}: "
                          f"{problem}; {CUTTING_FIX.format(n=n)}")
