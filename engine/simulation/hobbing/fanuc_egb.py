"""The Fanuc electronic gear box as the simulation follows it (issue 30; reference fanuc-egb.md
§F1–§F6): `G81 T<z2> L<±z0> [Q<m_n> P<β>]` (M series `G81.4 R<z2> L<±z0> …`) couples the table C
to the hob spindle, `G80` (`G80.4`) uncouples it. The verifier has read and bounded the block
(engine.verifier.synchronisation keeps |L|/T and the size of the Q/P factor for its bounds, and
T, L, Q, P with their signs on the statement, engine.verifier.statements.GearBox); here those
signed terms become the same DIN `Coupling` an 840D `EGON(C,"FINE",B,<num>,<den>,Z,<num>,<den>)`
gives (engine.simulation.hobbing.coupling), so one set of physics proves both:

* T and L are EGON's denominator and numerator, L = σ·z0 with σ = −h_hob·c_direction·b_direction
  (§F5), and k_B = c·b·L/T = −h_hob·z0/z2 in the DIN frame;
* Q and P are EGON's Z term: the control turns C by egb_helix_sign·sin P·360/(π·T·Q) degrees per
  mm of Z in the program's senses (§F4, the sign the machine record states, §F5, §F7), which is
  c_direction·z_direction times that in the DIN frame; the walk holds it to
  k_Z = −h_gear·360·sin β/(π·m_n·z2) as it holds an EGON's.

What it cannot prove it refuses (fail closed):

* Q and P on a record that does not state `egb_helix_sign` (NULL): the hand they cut is unknown.
  On a spur gear any Q/P cuts a helix (or is a differential a spur gear has no use for).
* Q and P in the M series' G81.4: their units and the compensation they give are not in the
  retrieved manuals (§F3); §F4's formula is G81's ([15i-MA] p. 749), and egb_helix_sign's dry run
  proves a sign, not a formula.
* a G81 with the hob already turning: whether the next block waits until the table is in step is
  not known (§F7 egb_waits_for_sync); synchronised at rest, the table follows the run-up.
* a C word: the table already follows the hob (and Z, through Q/P); a C move on top turns it a
  second time (§F6: the program must not add it twice)."""
from __future__ import annotations

import math
import re

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...verifier.statements import GearBox, Statement
from .coupling import Coupling, read_coupling
from .frame import Senses
from .report import SimulationError, where

C_WORD = re.compile(r"(?<![A-Z])C[-+=]?[0-9.]")
# The least increments the control reads Q and P in (fanuc-egb.md §F1: 0.00001 mm; 0.0001° in
# [15i-MA], the coarser of the two sources): a program cannot state them finer, so the Z term
# they give is right to the effect of half of each, not to the digits a program chose to write.
Q_INCREMENT = 0.00001        # mm
P_INCREMENT = 0.0001         # degrees
FANUC_DIALECTS = frozenset({"fanuc", "fanuc-g81.4"})   # the records whose programs a control stores by O number


def read_g81(start: Statement, senses: Senses, helix_sign: int | None = None) -> Coupling:
    """The coupling a G81 (G81.4) gives, in the DIN frame: L over T (R), as EGON's numerator over
    its denominator, and Q/P as its Z term, signed by the record's `helix_sign` (a G81 with Q and P
    on a record without one is refused before the walk). The terms are the verifier's, signs kept
    (engine.verifier.statements.GearBox)."""
    box = _gear_box(start)
    program, factors, resolution = {"B": box.threads / box.teeth}, {}, {}
    if box.module is not None and box.helix is not None and helix_sign is not None:
        program["Z"], resolution["Z"] = compensation(box.module, box.helix, box.teeth, helix_sign)
        factors["Z"] = program["Z"] * senses.factor("Z")
    return Coupling(box.threads, box.teeth, program["B"] * senses.factor("B"), factors, resolution, program,
                    start.name, box.ratio_words, box.helix_words)


def _gear_box(start: Statement) -> GearBox:
    assert start.gear_box is not None    # the verifier's reading of every G81/G81.4 carries it
    return start.gear_box


def read_start(start: Statement, code: str, senses: Senses, machine: Machine) -> Coupling:
    """The DIN coupling a start gives: an 840D EGON's (`code`, engine.simulation.hobbing.coupling)
    or a Fanuc G81's (G81.4's), whose Q/P the record's egb_helix_sign signs."""
    return read_coupling(code, senses) if start.name == "EGON" else read_g81(start, senses, machine.egb_helix_sign)


def compensation(module: float, helix: float, teeth: int, helix_sign: int) -> tuple[float, float]:
    """(degrees of C per mm of Z in the program's senses, its resolution) of the control's helical
    compensation (fanuc-egb.md §F4, metric input: the grammar refuses G20): helix_sign·sin P·360/
    (π·T·Q), Q the module in mm, P the helix angle in degrees. The resolution is what half a least
    increment of P and of Q changes it by (∂/∂P and ∂/∂Q of the formula)."""
    from ...verifier.synchronisation import helical_compensation  # Fanuc's Q/P only (issue 28: start-up)

    per_mm = helical_compensation(module, helix, teeth)
    scale = helical_compensation(module, 90.0, teeth)   # 360/(π·T·Q): sin 90° = 1
    by_p = scale * abs(math.cos(math.radians(helix))) * math.radians(P_INCREMENT / 2)
    return helix_sign * per_mm, by_p + abs(per_mm) * Q_INCREMENT / 2 / module


def compensation_problem(start: Statement, gear: Gear, helix_sign: int | None) -> str | None:
    """Why a G81 (G81.4, `start.name`) with Q and P cannot be proved for `gear` on a record stating
    `helix_sign` (None: the block gives neither, or the walk proves its Z term)."""
    given, command = _gear_box(start).helix_words, start.name
    if not given:
        return None
    if not gear.helix_angle:
        return (f"{given} on a spur gear: the control adds a helical differential Z·sin P·360/(π·T·Q) degrees of C "
                "per mm of Z (fanuc-egb.md §F4) and would cut a helix; a spur gear's G81 gives T and L only")
    if command != "G81":
        return (f"{given} in {command}: the M-series form's Q and P (their units, the compensation they give) are not "
                "in the retrieved manuals (fanuc-egb.md §F3); the simulation proves G81's helical compensation only "
                "(§F4), so it refuses a helical gear's G81.4 program")
    if helix_sign is None:
        return (f"the sign of the Fanuc helical compensation is not stated on the machine record (egb_helix_sign, "
                f"fanuc-egb.md §F5, §F7): the simulation cannot tell which hand {given} cuts and refuses a helical "
                "gear's Fanuc program")
    return None


def refuse_unproved_compensation(steps: list, gear: Gear, machine: Machine, name: str) -> None:
    """SimulationError at the first G81 (G81.4) whose Q and P the simulation cannot prove for `gear`
    on `machine`, or that starts with the hob already turning, before the walk: it cannot follow a
    table whose turning per mm of Z, or whose phase, it does not know."""
    turning = False
    for step in steps:
        if step.kind == "block" and {3, 5} & step.m_codes:
            turning = 3 in step.m_codes        # M3 counts at once: the unsafe way round for this rule
        if step.kind == "statement" and step.item.name in ("G81", "G81.4"):
            problem = (compensation_problem(step.item, gear, machine.egb_helix_sign)
                       or turning_start_problem(step.item.name, turning))
            if problem:
                raise SimulationError(f"{where(name, step.number, step.line)}: {problem}")


def g81_word_facts(steps: list, gear: Gear, hob: Hob):
    """(step, why, refuses) for each G81 (G81.4) whose words are not the gear's and the hob's; a
    fact after the walk, whose findings (another number of teeth, the wrong lead) say more."""
    for step in steps:
        if step.kind == "statement" and step.item.name in ("G81", "G81.4"):
            problem = words_problem(step.item, gear, hob)
            if problem:
                yield step, problem, True


def words_problem(start: Statement, gear: Gear, hob: Hob) -> str | None:
    """Why a G81's words are not the gear's and the hob's themselves (fanuc-egb.md §F5, §F6): T is
    a unit's teeth z2, |L| the hob's starts z0, Q the module m_n (mm) and |P| the helix angle β (°),
    each to half its least increment. T82 L-2 Q1.5 gives gear 43's ratio and Z term too, but only
    through §F4's derived arrangement of the control's formula, which no retrieved text shows."""
    box, command = _gear_box(start), start.name
    found = [problem for problem in (*_count_problems(box, gear, hob), *_helical_problems(box, gear)) if problem]
    if not found:
        return None
    written = f"{command} {box.ratio_words} {box.helix_words}".rstrip()
    return (f"{written}: {'; '.join(found)}: {command} writes the gear's and the hob's own numbers (T = z2, "
            "L = ±z0, Q = m_n, P = ±β, fanuc-egb.md §F5, §F6), not another pair with the same ratio")


def _count_problems(box: GearBox, gear: Gear, hob: Hob) -> tuple[str, str]:
    """T against the teeth of the gear's units, |L| against the hob's starts ('' where right)."""
    teeth = sorted({gear.teeth, *(unit.teeth for unit in gear.units)})
    return (f"{box.teeth_word} is not the teeth z2 {'/'.join(map(str, teeth))}" if box.teeth not in teeth else "",
            f"{box.threads_word} is not the hob's {hob.starts} starts" if abs(box.threads) != hob.starts else "")


def _helical_problems(box: GearBox, gear: Gear) -> tuple[str, ...]:
    """Q against m_n (mm), |P| against β (°), each to half its least increment ('' where right)."""
    if box.module is None or box.helix is None:
        return ()
    return (f"Q{box.module:g} is not the module {gear.module:g} mm"
            if abs(box.module - gear.module) > Q_INCREMENT / 2 + 1e-9 else "",
            f"P{box.helix:g} is not ±β {gear.helix_angle or 0:g}°"
            if abs(abs(box.helix) - (gear.helix_angle or 0.0)) > P_INCREMENT / 2 + 1e-9 else "")


def turning_start_problem(command: str, turning: bool) -> str | None:
    """A G81 with the hob spindle turning: the table must catch up with it, and whether the control
    holds the next block until C is in step is not in the retrieved manuals (fanuc-egb.md §F7
    egb_waits_for_sync; the 840D's EGON "FINE" does wait), so the first gaps could be cut out of
    step. Synchronised at rest, the table follows the hob's run-up in step."""
    if not turning:
        return None
    return (f"{command} with the hob spindle turning (M3, no M5 since): whether the control waits until the table "
            "is in step before the next block is not known (fanuc-egb.md §F7, egb_waits_for_sync), so the cut "
            f"could start out of step; {command} before M3")


def c_word_problem(code: str) -> str | None:
    """A C word in a Fanuc hobbing block (its code, the comment left out)."""
    if not C_WORD.search(code):
        return None
    return ("a C word: the table C follows the hob through G81 (and Z through Q/P); a C move turns it a second "
            "time: the program must not add it twice (fanuc-egb.md §F6)")


def program_number_facts(steps: list, gear: Gear, machine: Machine):
    """(step, why, refuses) for a Fanuc program whose O number is not the gear's on the machine,
    program_number_base + gear id (fanuc-egb.md §F7): the control stores a program by its O number,
    so gear 43's program written as O1044 (a template row edited, the record changed since) would
    replace gear 44's when it is read in. A record without program_number_base states no rule (no
    job is made for it, engine.hobbing.dialects); an 840D program is named, not numbered."""
    base = machine.program_number_base
    if machine.dialect not in FANUC_DIALECTS or base is None:
        return
    header = next((step for step in steps if step.kind == "header" and step.item.number is not None), None)
    if header is None or header.item.number != base + gear.id:
        shown = "no O number" if header is None else f"O{header.item.number:04d}"
        yield (header or steps[0], f"the program carries {shown}, gear {gear.id}'s program on {machine.name} is "
               f"O{base + gear.id:04d} (program_number_base {base} + gear id {gear.id}): read into the control "
               "it would replace another program (fanuc-egb.md §F7)", True)
