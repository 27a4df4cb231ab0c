"""The hobbing facts the simulation holds a program to from its own text and the records (gear,
hob, machine), never from the job or the model that made it (issue 26; design notes §7). One
row per rule, with the reference section it rests on; each yields (step, message, refuses) and
each message goes to the report with its line. The collisions, coupling, swivel, depth, feeds,
run-out, records named and cycle time are the walk's (engine.simulation.hobbing.walk, rules); the
feed marks are engine.simulation.hobbing.mark_facts', the floor-to-floor time floor_facts'."""
from __future__ import annotations

from collections.abc import Callable, Iterable

import msgspec

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...machines.work_holding import WorkHolding
from .cutting_speed import material_note
from .fanuc_egb import g81_word_facts, program_number_facts
from .floor_facts import floor_facts
from .frame import Senses
from .header_facts import gear_line_problem, hob_line_problem, table_problem, template_class, unit_line_problem
from .hob_fit import hob_fit_problem
from .holding_facts import holding_facts
from .mark_facts import mark_facts
from .program_facts import area_facts, cut_count_facts, cut_word_facts, speed_facts, tailstock_facts
from .report import Report


class Records(msgspec.Struct, frozen=True):
    """What the fact rules check the program's reading against: the gear, hob and machine records
    and the job's work-holding."""
    steps: list
    gear: Gear
    hob: Hob
    machine: Machine
    report: Report      # the walk's, for the cuts it found
    holding: WorkHolding | None = None   # the job's work-holding (None: the machine record's fixture)


def _hob_fits(records: Records):
    problem = hob_fit_problem(records.gear, records.hob)
    if problem:
        yield _hob_step(records.steps), problem, True


def _hob_step(steps):
    """The `; HOB` line names the hob; a program without one is refused at its first line."""
    return next((step for step in steps if step.line.startswith("; HOB ")), steps[0])


def _material_note(records: Records):
    note = material_note(records.gear, records.hob)
    if note and any(step.kind == "block" and step.item.speed is not None for step in records.steps):
        yield next(step for step in records.steps if step.kind == "block" and step.item.speed is not None), note, False


def _header_lines(records: Records):
    """GEAR, HOB, UNIT and the n0 line's table speed, each held to the records (§B4)."""
    template = template_class([step.line for step in records.steps])
    gear, hob, z_sense = records.gear, records.hob, Senses.of(records.machine).z
    for step in records.steps:
        if step.kind != "comment":
            continue
        line = step.line
        for problem in (gear_line_problem(line, gear, template), hob_line_problem(line, hob),
                        unit_line_problem(line, gear, z_sense), table_problem(line, gear, hob)):
            if problem:
                yield step, problem, True


def _units(records: Records) -> int:
    return 1 + len(records.gear.units)


class FactRule(msgspec.Struct, frozen=True):
    """A rule of the reference the program's values must agree with the records by, and its section."""
    name: str
    section: str
    check: Callable[[Records], Iterable[tuple]]


FACT_RULES = (
    FactRule("the hob fits the gear (module, pressure angle, class, hand, lead, length)", "§B, §B10, §B15", _hob_fits),
    FactRule("a gear material §C does not list: the widest row, noted", "§C", _material_note),
    FactRule("every S within §C for hob and gear material, and the header's n0", "§B4, §C",
             lambda r: speed_facts(r.steps, r.gear, r.hob)),
    FactRule("a Fanuc program's O number is the gear's on the machine", "fanuc-egb.md §F7",
             lambda r: program_number_facts(r.steps, r.gear, r.machine)),
    FactRule("a Fanuc G81's T, L, Q, P are z2, ±z0, m_n, ±β themselves", "fanuc-egb.md §F5, §F6",
             lambda r: g81_word_facts(r.steps, r.gear, r.hob)),
    FactRule("the tailstock clamped for every cut once the program clamps it", "§A3 (M20/M21 the builder's)",
             lambda r: tailstock_facts(r.steps)),
    FactRule("the working area set once, before the first move", "§A4", lambda r: area_facts(r.steps)),
    FactRule("GEAR, HOB, UNIT and table speed of the header are the records'", "§B4", _header_lines),
    FactRule("the header's FIXTURE is the work-holding the program is proved against", "issue 29",
             lambda r: holding_facts(r.steps, r.holding, r.machine.name)),
    FactRule("each cut's CLIMB/CONVENTIONAL/RADIAL/TANGENTIAL is its direction", "§B13, §B10",
             lambda r: cut_word_facts(r.steps, r.machine)),
    FactRule("the header's cuts and feed mode are the cuts'", "§B13, §B14",
             lambda r: cut_count_facts(r.steps, r.machine, r.report, _units(r))),
    FactRule("the header's floor-to-floor time is the program's at the machine's times", "§B16",
             lambda r: floor_facts(r.steps, r.machine, r.report)),
    FactRule("the last cut's feed marks within the depth the gear's grade allows", "§B6",
             lambda r: mark_facts(r.steps, r.gear, r.hob, r.report)),
)


def check_facts(steps, gear: Gear, hob: Hob, machine: Machine, report: Report,
                holding: WorkHolding | None = None) -> None:
    """Every FACT_RULES finding into the report."""
    if not steps:
        return
    records = Records(steps, gear, hob, machine, report, holding)
    for rule in FACT_RULES:
        for step, message, refuses in rule.check(records):
            report.add(step.number, step.line, message, refuses)
