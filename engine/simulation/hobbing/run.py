"""The simulation of one hobbing program against its gear, hob and machine (design notes §7,
issue 14): read with the verifier's reader, followed block by block (engine.simulation.hobbing.walk).
A program with the hob-shift-per-part clamp (R11 or Fanuc's #500 lies in an interval) is followed once with
the shift at each end of it."""
from __future__ import annotations

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...machines.work_holding import WorkHolding
from .facts import check_facts
from .fanuc_egb import refuse_unproved_compensation
from .reading import read_program
from .report import FirstRefusal, Report, SimulationError
from .solids import setup_solids, unit_solids
from .walk import BlockSimulation

SHIFT_ENDS = (0, 1)     # the low and the high end of the clamp's interval (R11, #500)


def simulate_program(lines: list[str], gear: Gear, hob: Hob, machine: Machine, name: str = "the program",
                     holding: WorkHolding | None = None, first_only: bool = False) -> Report:
    """The report of the program `lines` for `gear` cut with `hob` on `machine` (a hobber), the
    gear clamped on `holding` (None: the machine record's fixture and tailstock, issue 29);
    `first_only`, ended at the first refusal (Report.first_only: whether and why, for a search).
    Raises SimulationError only for a program (or machine) it cannot read."""
    if machine.kind != "hobber":
        raise SimulationError(f"machine {machine.name} is a {machine.kind}: the simulation follows hobbing programs")
    steps = read_program(lines, machine, name)
    refuse_unproved_compensation(steps, gear, machine, name)   # Fanuc Q/P: fanuc-egb.md §F5
    ends = SHIFT_ENDS if any(step.kind == "shift" for step in steps) else SHIFT_ENDS[:1]
    report = _follow(steps, lines, gear, hob, machine, name, ends[0], holding, first_only)
    for end in ends[1:]:
        if first_only and report.refused:
            return report
        other = _follow(steps, lines, gear, hob, machine, name, end, holding, first_only)
        report.findings.extend(finding for finding in other.findings if finding not in report.findings)
        report.table_speed = max(report.table_speed, other.table_speed)
    if not (first_only and report.refused):
        try:
            check_facts(steps, gear, hob, machine, report, holding)
        except FirstRefusal:
            pass   # the report has its first refusal
    return report


def prove_program(lines: list[str], gear: Gear, hob: Hob, machine: Machine, name: str = "the program",
                  holding: WorkHolding | None = None) -> Report:
    """The report, or SimulationError naming the first finding that refuses the program."""
    report = simulate_program(lines, gear, hob, machine, name, holding)
    if report.refused:
        raise report.error()
    return report


def _follow(steps, lines, gear: Gear, hob: Hob, machine: Machine, name: str, shift_end: int,
            holding: WorkHolding | None, first_only: bool = False) -> Report:
    worm_wheel = hob.purpose == "worm_wheel"
    units = unit_solids(gear, hob, worm_wheel)
    report = Report(name, first_only=first_only)
    setup = setup_solids(machine, units, hob, holding)
    walk = BlockSimulation(report, gear, hob, machine, units, setup, worm_wheel, shift_end)
    try:
        for step in steps:
            walk.take(step)
        walk.finish(lines)
    except FirstRefusal:
        pass   # the report has its first refusal
    return report
