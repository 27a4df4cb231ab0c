"""Constructs of an ISO lathe block whose effect the expander does not follow exactly, refused
naming the block and the construct (issue 27, adversary 27b H1, H2, H4, H5, H8, H13, H14, H16,
H17, L1, L2, and the decimal point of a cycle's contour blocks). Each rule is the control's
behaviour the plain lines would otherwise miss; the facts and their sources are in
docs/reference/iso-lathe.md ("Refused: a control would run it otherwise")."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import engine.verifier.expanders.cycles as cycles
import engine.verifier.expanders.iso_modes as iso_modes

from ..arcs import ARC_TOLERANCE

if TYPE_CHECKING:
    from .cycles import Move
    from .iso_lines import Source
    from .iso_modes import Modes

AXES = frozenset({"X", "Z", "U", "W"})
# The words a subprogram call or return carries (Fanuc M98 P L, Haas M97 P L, M99); any other
# word is executed by the control in the same block (a move first, then the call), which the
# expander does not follow.
CALL_WORDS = {98: frozenset({"P", "L"}), 97: frozenset({"P", "L"}), 99: frozenset()}
# The words each form of a cycle block is read with (iso_cycles): first block, second block (or
# the Haas one-block form). A word outside them (an S, T, G99, M05 …) the control executes with
# the cycle, and the expander would drop.
CYCLE_FORMS: dict[str, frozenset[str]] = {
    "70": frozenset({"P", "Q", "F"}),
    "71 first": frozenset({"U", "R"}), "71": frozenset({"P", "Q", "U", "W", "D", "F"}),
    "72 first": frozenset({"W", "R"}), "72": frozenset({"P", "Q", "U", "W", "D", "F"}),
    "73 first": frozenset({"U", "W", "R"}), "73": frozenset({"P", "Q", "U", "W", "D", "I", "K", "F"}),
    "74 first": frozenset({"R"}), "74": frozenset({"X", "Z", "U", "W", "P", "Q", "I", "K", "R", "F"}),
    "75 first": frozenset({"R"}), "75": frozenset({"X", "Z", "U", "W", "P", "Q", "I", "K", "R", "F"}),
    "76 first": frozenset({"P", "Q", "R"}), "76": frozenset({"X", "Z", "U", "W", "R", "P", "Q", "F"}),
    "76 haas": frozenset({"X", "Z", "K", "D", "A", "I", "F"}),
}
# D is a length in G71/G72 (Haas depth of cut) and G76 (Haas first pass): without a point a
# Fanuc 10/11-format control reads it in the least input increment (D2000 = 2 mm).
D_LENGTH = frozenset({"71", "72", "76 haas"})
# P and Q of G74–G76 count the least input increment (P2000 = 2 mm): a point in them is an alarm
# on a Fanuc, and the expander would read P1.5 as 0.0015 mm.
WHOLE_INCREMENTS = frozenset({"74", "75", "76 first", "76"})


def check_call(source: Source, code: int) -> None:
    """H1, H4, H5, H17: an M98/M97/M99 block carries its P (and L) only."""
    name = f"M{code}"
    for letter, text in source.words:
        if letter == "M" and text.isdigit() and int(text) == code:
            continue
        if code == 99 and letter == "P":
            raise source.refuse(f"M99 P{text} returns to sequence number N{text} of the calling program, which the "
                                "expander does not follow: return with a plain M99")
        if code == 98 and letter == "Q":
            raise source.refuse(f"M98 Q{text} starts the subprogram at its N{text}, which the expander does not "
                                "follow: call it from its top")
        if letter not in CALL_WORDS[code]:
            raise source.refuse(f"{name} with {letter}{text} in the same block: write them on separate blocks "
                                "(the control executes both, the expander follows only the call)")
    words = dict(source.words)
    if code == 98 and len(words.get("P", "")) > 4 and "L" not in words:
        number = words["P"]
        raise source.refuse(f"M98 P{number} is read by a Fanuc as {int(number) // 10000} repeat(s) of "
                            f"O{int(number) % 10000:04d} and by a Haas as O{int(number)}: write P with the 4-digit "
                            "program number and L for the repeats")


def check_block(source: Source, g_codes: list[int], words: dict[str, str], modes: Modes) -> None:
    """H8 and H16 on a block that is not a cycle."""
    if "T" in words and (AXES & words.keys() or 28 in g_codes):
        raise source.refuse(f"T{words['T']} with a move in the same block: a tool change in a block that moves "
                            "may index the turret while the slides move (the builder's order); write the T on a "
                            "block of its own")
    if 97 in g_codes and "S" not in words and modes.css:
        raise source.refuse("G97 without S after G96: the spindle keeps the speed G96 last gave it at the present "
                            "diameter, not an earlier G97 S; state S")


def cycle_form(code: int, words: dict[str, str]) -> str:
    """Which form of the cycle the block is, as engine.verifier.expanders.iso_cycles reads it."""
    if code == 70:
        return "70"
    if code == 76 and ("K" in words or "D" in words):
        return "76 haas"
    if code in (71, 72, 73):
        return str(code) if "P" in words else f"{code} first"
    return str(code) if AXES & words.keys() else f"{code} first"


def check_cycle(source: Source, code: int, g_codes: list[int], words: dict[str, str], modes: Modes) -> None:
    """H2, H13, L1: a cycle block carries only the words its form is read with."""
    others = [g for g in g_codes if g != code]
    if others:
        raise source.refuse(f"G{others[0]} on the G{code} cycle block: the control applies it with the cycle, "
                            "which the expander does not follow; write it on a block of its own before the cycle")
    form = cycle_form(code, words)
    for letter, text in source.words:
        if letter == "M" or (letter != "G" and letter not in CYCLE_FORMS[form]):
            raise source.refuse(f"{letter}{text} on the G{code} cycle block is not followed (the control applies "
                                "it with the cycle): write it on a block of its own before the cycle")
    _check_cycle_numbers(source, code, form, words, increment_input(modes))


def _check_cycle_numbers(source: Source, code: int, form: str, words: dict[str, str], increment: bool) -> None:
    if form in ("74", "75") and float(words.get("R", "0")) != 0:
        raise source.refuse(f"R{words['R']} on the second G{code} block is the relief at the bottom of each cut, "
                            "which the expander does not follow: leave it out (or R0)")
    if increment and form in D_LENGTH and "D" in words and "." not in words["D"] and float(words["D"]) != 0:
        raise source.refuse(f"D{words['D']} on the G{code} block needs a decimal point: a Fanuc 10/11-format control "
                            f"reads it in the least input increment; write D{words['D']}.")
    for letter in ("P", "Q"):
        if form in WHOLE_INCREMENTS and "." in words.get(letter, ""):
            raise source.refuse(f"{letter}{words[letter]} on the G{code} block is a whole number of the least input "
                                "increment (0.001 mm); a point in it is an alarm on the control")



def check_type_one(source: Source, code: int, where: tuple[list[Source], dict[int, int]], contour: list[Move]) -> None:
    """H14: G71/G72 are followed as Fanuc type I only: the first contour block moves across the
    passes alone (G71: X/U, no Z/W; a Z there makes it type II, which roughs pockets), and the
    contour goes one way in X and in Z (a pocket is roughed otherwise, or is an alarm)."""
    sources, labels = where
    first = sources[labels[int(float(dict(source.words)["P"]))]]
    along = ("Z", "W") if code == 71 else ("X", "U")
    for letter, text in first.words:
        if letter in along:
            raise first.refuse(f"{letter}{text} in the first contour block of G{code} makes it type II (pockets), "
                               f"which the expander does not follow: move only in {'X' if code == 71 else 'Z'} there")
    points = cycles.polyline((contour[0].x, contour[0].z), contour[1:]) if contour else []
    for axis, name in ((0, "X"), (1, "Z")):
        steps = [b[axis] - a[axis] for a, b in zip(points, points[1:])]
        if any(step > 1e-6 for step in steps) and any(step < -1e-6 for step in steps):
            raise source.refuse(f"the contour of G{code} goes back in {name} (a pocket): the expander follows type I "
                                f"roughing only, whose contour goes one way in X and in Z")


def check_centre(block: Source, centre: tuple[float, float], start: tuple[float, float],
                 end: tuple[float, float]) -> None:
    """L2: an arc by its centre I/K (radius values from the start; x diameters) whose end is not
    on the circle through its start, beyond the tolerance the 840D and LinuxCNC readers allow
    (engine.verifier.arcs.ARC_TOLERANCE): a Fanuc alarms (PS0020) or spirals; refused."""
    cx, cz = start[0] / 2 + centre[0], start[1] + centre[1]
    radii = [math.hypot(x / 2 - cx, z - cz) for x, z in (start, end)]
    if abs(radii[0] - radii[1]) > ARC_TOLERANCE or radii[0] == 0:
        raise block.refuse(f"the arc centre is {radii[0]:.3f} mm from the start and {radii[1]:.3f} mm from the end: "
                           "no arc of one radius joins them")


def check_contour_points(block: Source, modes: Modes) -> None:
    """A contour block N<P>…N<Q> is read by the cycle, never by the block walk: its dimension
    words need their decimal point all the same (X20 is 0.020 mm under input type I)."""
    if not increment_input(modes):
        return
    try:
        iso_modes.check_points(block.words)
    except ValueError as error:
        raise block.refuse(f"{error} (a block of a cycle's contour)") from None


def increment_input(modes: Modes) -> bool:
    """Whether a number without a point is read in the least input increment (Fanuc input type I,
    the default). Under pocket-calculator input (a record's decimal_point_input 'calculator') it is
    mm, as the expander reads it, so the point rules above do not apply."""
    return getattr(modes.machine, "decimal_point_input", "increment") != "calculator"


# Codes of one modal group: a record that lists two of them does not say which the control is in.
POWER_ON_GROUPS = (("G20", "G21"), ("G94", "G95", "G98", "G99"), ("G96", "G97"))


def power_on_fault(codes: list[str], gcode_system: str | None) -> str | None:
    """Why the record's power_on cannot be taken as the state a program starts in, or None.
    G20/G21: a Fanuc keeps the units the program before set, across reset and M30 (the clear state
    leaves them), so only the program may state them. G90 on G-code system A is the turning cycle,
    not a mode (system A has no G90/G91 distance mode)."""
    units = [code for code in codes if code in ("G20", "G21")]
    if units:
        return (f"the machine record's power_on lists {' and '.join(units)}: a Fanuc keeps the units the "
                "program before it set (reset and M30 leave them): only the program may state them")
    if gcode_system == "A" and "G90" in codes:
        return "the machine record's power_on lists G90, which on G-code system A is the turning cycle, not a mode"
    for group in POWER_ON_GROUPS:
        listed = [code for code in codes if code in group]
        if len(listed) > 1:
            return f"the machine record's power_on lists {' and '.join(listed)}, one modal group: which holds?"
    return None
