"""The simulation of one hobbing program against its gear, hob and machine (design notes §7,
issue 14): read with the verifier's reader, followed block by block (engine.simulation.hobbing.walk).
A program with the hob-shift-per-part clamp (R11 lies in an interval) is followed once with
the shift at each end of it."""
from __future__ import annotations

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...machines.work_holding import WorkHolding
from .facts import check_facts
from .reading import read_program
from .report import Report, SimulationError
from .solids import setup_solids, unit_solids
from .walk import BlockSimulation

SHIFT_ENDS = (0, 1)     # the low and the high end of the R11 interval


def simulate_program(lines: list[str], gear: Gear, hob: Hob, machine: Machine, name: str = "the program",
                     holding: WorkHolding | None = None) -> Report:
    """The report of the program `lines` for `gear` cut with `hob` on `machine` (a hobber), the
    gear clamped on `holding` (None: the machine record's fixture and tailstock, issue 29).
    Raises SimulationError only for a program (or machine) it cannot read."""
    if machine.kind != "hobber":
        raise SimulationError(f"machine {machine.name} is a {machine.kind}: the simulation follows hobbing programs")
    steps = read_program(lines, machine, name)
    ends = SHIFT_ENDS if any(step.kind == "shift" for step in steps) else SHIFT_ENDS[:1]
    reports = [_follow(steps, lines, gear, hob, machine, name, end, holding) for end in ends]
    report = reports[0]
    for other in reports[1:]:
        for finding in other.findings:
            report.add(finding.number, finding.line, finding.message, finding.refuses)
        report.table_speed = max(report.table_speed, other.table_speed)
    check_facts(steps, gear, hob, machine, report, holding)
    return report


def prove_program(lines: list[str], gear: Gear, hob: Hob, machine: Machine, name: str = "the program",
                  holding: WorkHolding | None = None) -> Report:
    """The report, or SimulationError naming the first finding that refuses the program."""
    report = simulate_program(lines, gear, hob, machine, name, holding)
    if report.refused:
        raise report.error()
    return report


def _follow(steps, lines, gear: Gear, hob: Hob, machine: Machine, name: str, shift_end: int,
            holding: WorkHolding | None) -> Report:
    worm_wheel = hob.purpose == "worm_wheel"
    units = unit_solids(gear, hob, worm_wheel)
    report = Report(name)
    setup = setup_solids(machine, units, hob, holding)
    walk = BlockSimulation(report, gear, hob, machine, units, setup, worm_wheel, shift_end)
    for step in steps:
        walk.take(step)
    walk.finish(lines)
    return report
