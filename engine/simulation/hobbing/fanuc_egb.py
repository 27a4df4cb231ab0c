"""The Fanuc electronic gear box as the simulation follows it (issue 30; reference fanuc-egb.md
§F1–§F6): `G81 T<z2> L<±z0> [Q<m_n> P<β>]` (M series `G81.4 R<z2> L<±z0> …`) couples the table C
to the hob spindle, `G80` (`G80.4`) uncouples it. The verifier has read and bounded the block
(engine.verifier.synchronisation keeps only |L|/T); here its signed terms become the same DIN
`Coupling` an 840D `EGON(C,"FINE",B,<num>,<den>)` gives (engine.simulation.hobbing.coupling), so
one set of physics proves both: T and L are EGON's denominator and numerator, L = σ·z0 with
σ = −h_hob·c_direction·b_direction (§F5), and k_B = c·b·L/T = −h_hob·z0/z2 in the DIN frame.

What it cannot prove it refuses (fail closed):

* Q and P, the control's own helical differential Z·sin P·360/(π·T·Q) degrees of C per mm of Z
  (§F4): the sign with which the control applies P is not in the retrieved manuals and the
  machine record has no `egb_helix_sign` yet (§F5, §F7), so the hand it cuts is unknown. On a
  spur gear any Q/P cuts a helix (or is a differential a spur gear has no use for).
* a C word: the table already follows the hob (and Z, through Q/P); a C move on top turns it a
  second time (§F6: the program must not add it twice)."""
from __future__ import annotations

import re

from ...gears.records import Gear
from .coupling import Coupling
from .frame import Senses
from .report import SimulationError, where

COUPLING_ON = frozenset({"EGON", "G81", "G81.4"})         # start (or re-rate) the table's coupling
COUPLING_OFF = frozenset({"EGOFS", "EGDEL", "G80", "G80.4"})
G_CODE = re.compile(r"G0*8[01](?:\.4)?")
WORD = re.compile(r"([A-Z])([-+]?[0-9.]+)")
C_WORD = re.compile(r"(?<![A-Z])C[-+=]?[0-9.]")
HELICAL_WORDS = ("Q", "P")


def g81_words(code: str) -> dict[str, str]:
    """address -> text of a G81/G81.4 block's words (the verifier has checked each once)."""
    words = {}
    for token in code.split():
        match = WORD.fullmatch(token)
        if match is not None and not G_CODE.fullmatch(token):
            words[match.group(1)] = match.group(2)
    return words


def read_g81(code: str, senses: Senses) -> Coupling:
    """The coupling a G81 (G81.4) block gives, in the DIN frame: L over T (R), as EGON's numerator
    over its denominator; no Z or Y term (a G81 with Q and P is refused before the walk)."""
    words = g81_words(code)
    teeth = int(words["T"] if "T" in words else words["R"])
    threads = int(words["L"])
    return Coupling(threads, teeth, threads / teeth * senses.factor("B"), {}, {}, {"B": threads / teeth})


def compensation_problem(code: str, gear: Gear) -> str | None:
    """Why a G81 with Q and P cannot be proved for `gear` (None: the block gives neither)."""
    words = g81_words(code)
    if not any(address in words for address in HELICAL_WORDS):
        return None
    given = " ".join(f"{address}{words[address]}" for address in HELICAL_WORDS if address in words)
    if not gear.helix_angle:
        return (f"{given} on a spur gear: the control adds a helical differential Z·sin P·360/(π·T·Q) degrees of C "
                "per mm of Z (fanuc-egb.md §F4) and would cut a helix; a spur gear's G81 gives T and L only")
    return (f"the sign of the Fanuc helical compensation is not stated on the machine record (egb_helix_sign, "
            f"fanuc-egb.md §F5, §F7): the simulation cannot tell which hand {given} cuts and refuses a helical "
            "gear's Fanuc program")


def refuse_unproved_compensation(steps: list, gear: Gear, name: str) -> None:
    """SimulationError at the first G81 (G81.4) whose Q and P the simulation cannot prove for `gear`,
    before the walk: it cannot follow a table whose turning per mm of Z it does not know."""
    for step in steps:
        if step.kind == "statement" and step.item.name in ("G81", "G81.4"):
            problem = compensation_problem(step.line.partition(";")[0], gear)
            if problem:
                raise SimulationError(f"{where(name, step.number, step.line)}: {problem}")


def c_word_problem(code: str) -> str | None:
    """A C word in a Fanuc hobbing block (its code, the comment left out)."""
    if not C_WORD.search(code):
        return None
    return ("a C word: the table C follows the hob through G81 (and Z through Q/P); a C move turns it a second "
            "time: the program must not add it twice (fanuc-egb.md §F6)")
