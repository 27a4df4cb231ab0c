"""A template run for one job with its program verified for the machine: the one way the result
table of a program that may be stored is made (new gears, stored jobs made again, turning jobs
from drawings), so no route stores lines the verifier has not read. On a hobber the program is
also simulated against the gear and hob records (engine.simulation): nothing the simulation
refuses is stored. A turning job's program (a drawing's job, classes turning_iso/turning_840d)
is simulated against the job's drawing record (engine.simulation.turning.drawing: its profile,
blank, tool-change position and materials) and its stored operations (module_params), not
against the passes the planner computed. The records come from the database, not from the job's parameters, which
a runner may have edited. A class job's program on a lathe (a class without a model,
engine.programs.class_jobs) has no drawing record: it is simulated against the blank its
parameters state, or the one its program implies (engine.simulation.turning.undrawn), and the
simulation's "not checked" list becomes the program's notes. The one exception is a class job
stored with --unverified: its record and lineage line say UNVERIFIED, and it is never written
to a file for the machine."""
from __future__ import annotations

import msgspec

from ..errors import EngineError
from ..gears.records import Gear, Hob
from ..machines.records import Machine
from ..machines.work_holding import WorkHolding
from ..nc.lineage import refuse_lineage_shaped
from ..simulation import SimulationError, simulate_program
from ..simulation.turning import BLANK_PARAMS
from ..templates.decision_table import Result, compiled_template
from ..templates.rows import Template
from ..verifier import verify_program


class Workpiece(msgspec.Struct, frozen=True):
    """What a hobbing program is proved against: the gear (with its units) and the hob, as stored,
    and the job's work-holding (None: the machine record's fixture and tailstock, issue 29)."""
    gear: Gear
    hob: Hob
    holding: WorkHolding | None = None


class TurningWork(msgspec.Struct, frozen=True):
    """What a lathe program is proved against: the job's parameters and module parameters with
    the facts of its drawing record in place of the job's (the profile, the blank, the tool-change
    position, the materials: engine.simulation.turning.drawing.proof_params), and its operations."""
    params: dict
    module_params: dict
    notes: list = []   # filled by the proof: what it did not check

    def __eq__(self, other: object) -> bool:
        """The params and module params: the proof's notes are not compared."""
        return (isinstance(other, TurningWork) and self.params == other.params
                and self.module_params == other.module_params)


def class_work(params: dict) -> TurningWork:
    """What a class job's lathe program is proved against: its params' blank, nothing else (no
    profile, no operations: the simulation then proves it without a drawing record)."""
    return TurningWork({name: params[name] for name in BLANK_PARAMS if name in params}, {})


# The classes whose jobs come from drawings (engine.programs.turning_jobs): their programs must be
# proved by the turning simulation against the drawing record. Every other lathe program (a class
# job) is proved against a blank (class_work).
TURNING_CLASSES = frozenset({"turning_iso", "turning_840d"})


def run_template(template: Template, params: dict, module_params: dict, machine: Machine,
                 workpiece: Workpiece | TurningWork | None = None) -> Result:
    """Evaluate the decision table, verify the program for the machine (engine.verifier)
    and prove it by simulation: on a hobber against the gear and hob `workpiece`, on a lathe
    (a turning class's job) against the job's records `workpiece`."""
    result = compiled_template(template).run(params, module_params)
    name = params.get("program_name") if isinstance(params, dict) else None
    name = name if isinstance(name, str) else None
    refuse_lineage_shaped(name or "the program", result.lines)
    verify_program(result.lines, machine, name)
    if machine.kind == "hobber":
        prove(result.lines, machine, workpiece, name or "the program")
    elif machine.kind == "lathe":
        if workpiece is None and not from_drawing(template, params):
            workpiece = class_work(params)
        prove_lathe(result.lines, machine, workpiece, name or "the program")
    return result


def from_drawing(template: Template, params) -> bool:
    """A turning class's job, or any job whose parameters carry a drawing's profile."""
    return template.gear_class in TURNING_CLASSES or (isinstance(params, dict) and "profile" in params)


def prove_lathe(lines: list[str], machine: Machine, work: Workpiece | TurningWork | None, name: str) -> None:
    """SimulationError (nothing stored) for a lathe program the turning simulation refuses. The
    turning simulation (shapely) is imported here, by lathe programs only: a hobbing command never
    loads it (issue 28)."""
    from ..simulation.turning.run import simulate_turning
    if not isinstance(work, TurningWork):
        raise EngineError(f"{name}: a turning program needs its job's records (profile, blank, operations) to be "
                          "proved by the simulation; nothing stored")
    report = simulate_turning(lines, work.params, work.module_params, machine, name)
    if report.refused:
        raise SimulationError(f"{report.error()}; nothing stored")
    if report.not_checked:
        work.notes.append(f"turning simulation: followed {report.rapids} rapid(s) and {report.cut_moves} cut(s) "
                          f"through the blank {report.blank}: no rapid through material, no cut with the spindle "
                          "stopped, no tool change inside the blank")
        work.notes.extend(f"not checked: {what}" for what in report.not_checked)


def prove(lines: list[str], machine: Machine, workpiece: Workpiece | TurningWork | None, name: str) -> None:
    """SimulationError (nothing stored) for a program the simulation refuses."""
    if not isinstance(workpiece, Workpiece):
        raise EngineError(f"{name}: a hobbing program needs its gear and hob to be proved by the simulation; "
                          "nothing stored")
    # a program refused is refused at its first finding: the search tries the next choice, the
    # refusal names that finding (engine simulate lists every finding of a stored program)
    report = simulate_program(lines, workpiece.gear, workpiece.hob, machine, name, workpiece.holding,
                              first_only=True)
    if report.refused:   # named by the gear: the id the user gave (a batch names each bad gear)
        raise SimulationError(f"gear {workpiece.gear.id}: {report.error()}; nothing stored")
