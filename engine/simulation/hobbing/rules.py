"""Rules the simulation holds a hobbing program to beyond collisions and the coupling's terms
(reference §B8, §B15, §C; design notes §7): what may not move while the table is coupled, where
the generating zone must lie on the hob, the least run-out, the most feed per workpiece
revolution, and that the program names and selects the records it is proved against."""
from __future__ import annotations

import math
import re

from ...gears.cutting_data import feed_limit, table_maximum
from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...machines.work_holding import KINDS as WORK_HOLDING_KINDS
from .chips import chip_problem

TOOTH_DEPTH = 2.25        # h = 2.25·m_n (§B15)
WORK_OFFSETS = (54, 55, 56, 57)
POSITION_TOLERANCE = 1e-9
FEED_TOLERANCE = 1e-6     # relative: a feed written at the bound is at the bound


def moves(position: dict, axis: str, value: float) -> bool:
    """An axis written while coupled moves unless it is known to stand at `value` already."""
    return axis not in position or abs(position[axis] - value) > POSITION_TOLERANCE


def coupled_shift_problem(coupling) -> str | None:
    """§B15: a shift made in the cut turns the work against the gaps already cut unless Y is a
    leading axis of the coupling (a tangential worm wheel's Y term)."""
    if "Y" in coupling.factors:
        return None
    if coupling.command != "EGON":
        command = coupling.command
        return (f"the hob shift Y moves while the table is synchronised by {command}, which has no Y term: the table "
                f"keeps its phase while the hob's thread moves along the teeth (§B15); shift before {command}")
    return ("the hob shift Y moves while the table is coupled and Y is not a leading axis of the EGON: the table "
            "keeps its phase while the hob's thread moves along the teeth (§B15); shift before EGDEF/EGON (Fanuc: G81)")


def coupled_swivel_problem() -> str:
    return ("the swivel A moves while the table is coupled (the hob still in the gaps): the thread leaves the "
            "tooth direction; swivel before EGDEF/EGON (G81) or after EGOFS (G80) with the hob clear")


def recut_problem(unit_name: str, command: str = "EGON") -> str:
    """A unit cut under two couplings: neither EGON "FINE" nor a Fanuc G81 (`command`) brings the
    table back to the phase of the gaps cut before."""
    start = 'EGON "FINE" does not synchronise' if command == "EGON" else f"a new {command} sets no phase"
    return (f"the cut enters {unit_name}, which an earlier coupling already cut: {start}, so this coupling's phase is "
            "arbitrary against the gaps cut before; rough and finish a unit in one coupling")


def generating_length(gear: Gear) -> float:
    """L_gen = 2·h/tan α_n + π·m_n, h = 2.25·m_n (§B15)."""
    depth = TOOTH_DEPTH * gear.module
    return 2 * depth / math.tan(math.radians(gear.pressure_angle)) + math.pi * gear.module


def zone_problem(shift: float, gear: Gear, hob: Hob) -> str | None:
    """|Y| + L_gen/2 ≤ L/2: the whole generating zone lies on the hob (§B15)."""
    zone = generating_length(gear)
    if abs(shift) + zone / 2 <= hob.length / 2 + POSITION_TOLERANCE:
        return None
    return (f"the generating zone ({zone:.1f} mm long, §B15) at shift Y{shift:g} reaches "
            f"{abs(shift) + zone / 2:.1f} mm from the middle of hob {hob.id}, {hob.length:g} mm long "
            f"(at most {max(0.0, (hob.length - zone) / 2):.1f} mm of shift): the hob cuts with missing teeth")


def least_run_out(gear: Gear, swivel: float) -> float:
    """§B8: the generating zone reaches (h/tan α_n)·sin|η| along the work axis beyond the hob centre."""
    depth = TOOTH_DEPTH * gear.module
    return depth / math.tan(math.radians(gear.pressure_angle)) * math.sin(math.radians(abs(swivel)))


def run_out_problem(run_out: float | None, least: float, unit: str) -> str | None:
    if run_out is None or (run_out > 0 and run_out >= least - 1e-6):
        return None
    if run_out <= 0:
        return (f"the pass ends {-run_out:.3f} mm short of carrying the hob centre beyond the face of {unit} it "
                f"leaves (no run-out; at least {least:.3f} mm, §B8)")
    return (f"the pass carries the hob centre only {run_out:.3f} mm beyond the face of {unit} it leaves; the "
            f"generating zone reaches {least:.3f} mm past the centre at this swivel ((h/tan α_n)·sin|η|, §B8)")


def feed_problem(feed: float | None, gear: Gear, hob: Hob, motion: str = "pass") -> str | None:
    """§C, §C1: the roughing maximum f_a for the gear and hob bounds every pass, rough or finish:
    the table's for the module, and for a cylindrical gear the feed whose chips (Hoffmeister's
    h_max at the whole tooth depth) stay within the allowed thickness, worked out here from the
    feed (engine.simulation.hobbing.chips), not the planner's bound."""
    if feed is None:
        return None
    if hob.purpose == "worm_wheel":
        most, why = feed_limit(gear, hob, "rough")
    else:
        most, why = table_maximum(gear.module, "rough"), f"roughing maximum for m{gear.module:g} (reference §C)"
    if feed > most * (1 + FEED_TOLERANCE):
        return f"the {motion} feeds {feed:.3f} mm per workpiece revolution, above the {most:.3g} mm/rev {why}"
    return None if hob.purpose == "worm_wheel" else chip_problem(feed, gear, hob, motion)


HEADERS = {"GEAR": re.compile(r";\s*GEAR\s+(\S+)"), "HOB": re.compile(r";\s*HOB\s+(\S+)"),
           "MACHINE": re.compile(r";\s*MACHINE\s+(\S+)")}
HOB_HAND = re.compile(r"\bhand=(\S+)")


def record_header_problem(line: str, gear: Gear, hob: Hob, machine: Machine) -> str | None:
    """A header comment `; GEAR <id>`, `; HOB <id> … hand=<h>`, `; MACHINE <name>` must name
    the records the program is proved against: a program for another part is not this one's."""
    wanted = {"GEAR": str(gear.id), "HOB": hob.id, "MACHINE": machine.name}
    for record, pattern in HEADERS.items():
        found = pattern.match(line)
        if found and found.group(1) != wanted[record]:
            return (f"the header names {record.lower()} {found.group(1)}; the program is proved against "
                    f"{record.lower()} {wanted[record]}")
    hand = HOB_HAND.search(line) if HEADERS["HOB"].match(line) else None
    if hand and hand.group(1) != (hob.hand or "R"):
        return f"the header names a hob of hand {hand.group(1)}; hob {hob.id} is hand {hob.hand}"
    return None


def block_record_problem(step, hob: Hob, machine: Machine) -> str | None:
    """The work offset selected must be the machine record's, the tool called the hob record's."""
    for code in step.g_codes & set(WORK_OFFSETS):
        if f"G{code}" != machine.work_offset:
            return (f"the program selects work offset G{code}; {machine.name} clamps its work at "
                    f"{machine.work_offset} (machine record)")
    tool = step.item.values.get("T")
    if tool is not None and tool != hob.tool_number:
        return f"the program calls tool T{tool:g}; hob {hob.id} is tool T{hob.tool_number} (hob record)"
    offset = step.item.values.get("D")
    if offset is not None and offset != 1:
        return f"the program selects tool offset D{offset:g}; the hob has one edge, D1"
    return None


def coupled_tool_problem(values: dict) -> str | None:
    """The tool and its offset are set before the coupling: changed in it, the hob's position jumps."""
    words = [address for address in ("T", "D") if address in values]
    if not words:
        return None
    return (f"{'/'.join(words)} written while the table is coupled: the tool and its offset (T<n> D1) are "
            "selected before EGON (Fanuc: G81)")


def setup_advice(solid_name: str) -> str:
    """What to do about a machine part too big for the gear."""
    if solid_name == "the tailstock":
        return ("; clamp without the tailstock (--no-tailstock) or use a smaller tailstock/fixture in the "
                "machine record")
    if solid_name == "the fixture":
        return ("; use a smaller fixture (a work-holding sized for the gear: `engine fixtures match --gear ID`, "
                "`engine instantiate --fixture ID`) or a larger fixture_gap (a spacer) in the machine record")
    if solid_name.startswith("the ") and solid_name.split()[1] in WORK_HOLDING_KINDS:
        return "; choose a work-holding that clears the root (`engine fixtures match --gear ID`)"
    return ""
