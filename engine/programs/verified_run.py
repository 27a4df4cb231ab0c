"""A template run for one job with its program verified for the machine: the one way the result
table of a program that may be stored is made (new gears, stored jobs made again, turning jobs
from drawings), so no route stores lines the verifier has not read. On a hobber the program is
also simulated against the gear and hob records (engine.simulation): nothing the simulation
refuses is stored. The records come from the database, not from the job's parameters, which
a runner may have edited. The one exception is a class job stored with --unverified
(engine.programs.class_jobs): its record and lineage line say UNVERIFIED, and it is never
written to a file for the machine."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import EngineError
from ..gears.records import Gear, Hob
from ..machines.records import Machine
from ..nc.lineage import refuse_lineage_shaped
from ..simulation import SimulationError, simulate_program
from ..templates.decision_table import Result, compiled_template
from ..templates.rows import Template
from ..verifier import verify_program


@dataclass(frozen=True, slots=True)
class Workpiece:
    """What a hobbing program is proved against: the gear (with its units) and the hob, as stored."""
    gear: Gear
    hob: Hob


def run_template(template: Template, params: dict, module_params: dict, machine: Machine,
                 workpiece: Workpiece | None = None) -> Result:
    """Evaluate the decision table, verify the program for the machine (engine.verifier)
    and, on a hobber, prove it by simulation against `workpiece`."""
    result = compiled_template(template).run(params, module_params)
    name = params.get("program_name") if isinstance(params, dict) else None
    name = name if isinstance(name, str) else None
    refuse_lineage_shaped(name or "the program", result.lines)
    verify_program(result.lines, machine, name)
    if machine.kind == "hobber":
        prove(result.lines, machine, workpiece, name or "the program")
    return result


def prove(lines: list[str], machine: Machine, workpiece: Workpiece | None, name: str) -> None:
    """SimulationError (nothing stored) for a program the simulation refuses."""
    if workpiece is None:
        raise EngineError(f"{name}: a hobbing program needs its gear and hob to be proved by the simulation; "
                          "nothing stored")
    report = simulate_program(lines, workpiece.gear, workpiece.hob, machine, name)
    if report.refused:   # named by the gear: the id the user gave (a batch names each bad gear)
        raise SimulationError(f"gear {workpiece.gear.id}: {report.error()}; nothing stored")
