"""The simulation of one lathe program against its job's records and the lathe (design notes
§8, issue 26): read with the verifier's reader, followed block by block (engine.simulation.
turning.follow), then through the material (engine.simulation.turning.material) and against
the cutting-data table (engine.simulation.turning.cutting). It reads only the program text,
the job's stored params and module_params and the machine record — never the model that
planned the passes (engine.turning). A class job's program (no drawing record: params without a
profile, no operations) is proved against a blank only, and the report says what it could not
check (engine.simulation.turning.undrawn)."""
from __future__ import annotations

from ...machines.records import Machine
from ..hobbing.report import SimulationError
from .cutting import check_cutting
from .follow import FEED, Move, ProgramState
from .material import MaterialWalk
from .reading import read_lathe_program
from .report import TurningReport
from .undrawn import NOT_CHECKED, check_tool_changes, program_blank, reference_point
from .work import TurningRecords, number, turning_records

# The most a cut may run on behind a stored blank's back end (mm): the planner's overtravel,
# engine.turning.defaults.CLEARANCE, as a fixed bound. The job's params.clearance is the runner's
# to edit; taken alone, clearance=31 let a pass run 30 mm into the bar the chuck holds.
BEHIND_RUN_OUT_MM = 2.0


def simulate_turning(lines: list[str], params: dict, module_params: dict, machine: Machine,
                     name: str = "the program") -> TurningReport:
    """The report of the lathe program `lines` for the job (params, module_params) on `machine`.
    Raises SimulationError only for a program (or machine) it cannot read."""
    if machine.kind != "lathe":
        raise SimulationError(f"machine {machine.name} is a {machine.kind}: the turning simulation follows "
                              "lathe programs")
    records = turning_records(params, module_params)
    report = TurningReport(name)
    start = records.tool_change or reference_point(machine)
    state = ProgramState(records, report, machine.dialect, start)
    for step in read_lathe_program(lines, machine, name):
        state.take(step)
    blank, assumed = _blank(state.moves, records)
    z0, r0, z1, r1 = blank.bounds
    report.blank = f"Ø{2 * r1:.3f} Z{z0:.3f}…{z1:.3f}" + (" (assumed)" if assumed else "")
    walk = MaterialWalk(records, blank, report, _run_out(params, records))
    for move in state.moves:
        walk.take(move)
    if records.drawn:
        check_cutting(state.moves, records, params, module_params, report)
    else:
        check_tool_changes(state.changes, blank, report)
        report.not_checked = list(NOT_CHECKED)
    report.findings.sort(key=lambda finding: finding.number)
    return report


def prove_turning(lines: list[str], params: dict, module_params: dict, machine: Machine,
                  name: str = "the program") -> TurningReport:
    """The report, or SimulationError naming the first finding that refuses the program."""
    report = simulate_turning(lines, params, module_params, machine, name)
    if report.refused:
        raise report.error()
    return report


def _blank(moves: list[Move], records: TurningRecords):
    """(the blank, whether assumed): a drawing job's (design notes §8) or a class job's (undrawn)."""
    if not records.drawn:
        return program_blank(moves, records.stock)
    return records.blank(_feed_radius(moves), _facing_zs(moves, records)), records.stock is None


def _run_out(params: dict, records: TurningRecords) -> float:
    """A class job has no params.clearance (the planner's overtravel): the fixed bound alone."""
    if not records.drawn and "clearance" not in params:
        return BEHIND_RUN_OUT_MM
    return min(number(params, "clearance"), BEHIND_RUN_OUT_MM)


def _feed_radius(moves: list[Move]) -> float:
    return max((r for move in moves if move.kind != "rapid" for _, r in move.points), default=0.0)


def _facing_zs(moves: list[Move], records) -> list[float]:
    """The Zs a FACE operation feeds along X at: the face it cuts stands there, so the blank does too."""
    zs = []
    for move in moves:
        op = records.operations.get(move.operation) if move.operation else None
        (z0, r0), (z1, r1) = move.points[0], move.points[-1]
        if op is not None and op.kind == "FACE" and move.kind == FEED and z0 == z1 and r0 != r1:
            zs.append(z0)
    return zs
