"""The words of one 840D lathe block, evaluated and written as the plain block the 840D lathe
grammar reads (engine.verifier.grammar LATHE_840D): absolute mm, X a diameter, the motion G code
in every moving block, numbers instead of expressions, arcs by their radius CR.

What each word does is a table (WORD_RULES, G_RULES, M_RULES): kept as written, changed to its
plain form, dropped (it moves nothing and the verifier checks nothing of it), or refused with
the reason. The modal state a plain block needs from earlier blocks is kept here: the motion
G0/G1/G2/G3/G33, radius or diameter programming (DIAMON/DIAMOF/DIAM90), the spindle clamp
LIMS (repeated in a G96 block, since the verifier reads each block on its own), and the
position (an arc given by its centre I/K needs its start point)."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import msgspec

from ..arcs import ARC_TOLERANCE
from ..numbers import plain_decimal
from ..refusals import Refused
from .sinumerik_expressions import evaluate
from .sinumerik_lines import Word

if TYPE_CHECKING:
    from ...machines.records import Machine

MOTIONS = (0, 1, 2, 3, 33)
CUTTING_MOTIONS = (1, 2, 3, 33)     # moves whose feed or lead depends on the spindle's r/min
# G codes kept in the plain block as written, and G codes written as another one
KEPT_G = frozenset({4, 18, 40, 71, 90, 94, 95, 96, 97})
SAME_AS = {710: 71}     # G710: metric, feeds included
DROPPED_G = frozenset({9, 60, 64, 601, 602, 603, 641, 642, 645})    # exact stop and path modes
WORK_OFFSETS = (54, 55, 56, 57)
REFUSED_G = {
    17: "G17 selects the XY plane of a milling program; a lathe program turns in the ZX plane (G18)",
    19: "G19 selects the YZ plane of a milling program; a lathe program turns in the ZX plane (G18)",
    91: "incremental G91 moves cannot be verified; program absolute positions (G90)",
    70: "G70 programs inches; every limit of the record is in mm (G71)",
    700: "G700 programs inches; every limit of the record is in mm (G71)",
    41: "tool-nose radius compensation G41/G42 moves the tool off the programmed contour by a nose "
        "radius the machine record does not hold; program the tool path (G40)",
    42: "tool-nose radius compensation G41/G42 moves the tool off the programmed contour by a nose "
        "radius the machine record does not hold; program the tool path (G40)",
    53: "G53 moves in the machine frame, in which the record's travel is not stated; program in its work offset",
    153: "G153 moves in the machine frame, in which the record's travel is not stated; program in its work offset",
    500: "G500 switches the work offset off: positions would be machine positions; use the record's offset",
    25: "G25/G26 limit the working area or the spindle speed on the control; the verifier holds the record's",
    26: "G25/G26 limit the working area or the spindle speed on the control; the verifier holds the record's",
    74: "G74/G75 move by way of a reference point the verifier cannot see",
    75: "G74/G75 move by way of a reference point the verifier cannot see",
}
KEPT_M = frozenset({3, 4, 5, 8, 9})
DROPPED_M = frozenset({0, 1, 6})   # a programmed stop; M6 on a turret: the T word is the change
END_M = frozenset({2, 30, 17})     # end of program (M17 ends a subprogram, the main program at top)
# words that move nothing the verifier checks: dropped from the plain block
DROPPED_WORDS = frozenset({"SF", "FNORM", "SOFT", "BRISK", "STOPRE", "CFTCP", "CFC", "CFIN"})
DROPPED_CALLS = frozenset({"MSG"})
DIAMETER_MODES = {"DIAMON": True, "DIAM90": True, "DIAMOF": False}
NOT_LATHE_AXES = frozenset({"Y", "A", "B", "C", "U", "V", "W"})
REFUSED_WORDS = {
    "SUPA": "SUPA moves in the machine frame, in which the record's travel is not stated; "
            "program in its work offset",
    "RND": "RND= rounds the corner between two moves: the verifier follows only programmed end points",
    "CHR": "CHR= chamfers the corner between two moves: the verifier follows only programmed end points",
    "CHF": "CHF= chamfers the corner between two moves: the verifier follows only programmed end points",
    "ANG": "ANG= gives a move by its angle: the verifier follows only programmed end points",
    "TRANS": "TRANS shifts every position by a frame the verifier cannot see",
    "ATRANS": "ATRANS shifts every position by a frame the verifier cannot see",
    "ROT": "ROT turns every position by a frame the verifier cannot see",
    "SCALE": "SCALE scales every position by a frame the verifier cannot see",
    "MIRROR": "MIRROR mirrors every position by a frame the verifier cannot see",
    "TRAFOOF": "TRAFOOF, TRANSMIT and TRACYL belong to milling on a lathe (a C axis); not a turning program",
    "TRANSMIT": "TRAFOOF, TRANSMIT and TRACYL belong to milling on a lathe (a C axis); not a turning program",
    "TRACYL": "TRAFOOF, TRANSMIT and TRACYL belong to milling on a lathe (a C axis); not a turning program",
    "CYCLE800": "CYCLE800 swivels the tool plane of a milling machine; not a turning program",
}


class BlockState(msgspec.Struct):
    """What earlier blocks left that the next plain block depends on."""
    machine: Machine
    motion: int | None = None
    diameter: bool = True            # DIAMON: X is a diameter (the control's lathe default, DIAMON stated)
    clamp: float | None = None       # LIMS, r/min
    rpm: float | None = None         # S under G97, r/min (a G4 S… dwell counts its turns at it)
    css: bool = False                # G96: S is a cutting speed in m/min, the r/min vary
    frozen: bool = False             # G97 without S after G96: the r/min G96 last reached, unknown here
    position: dict[str, float] = {}   # X (diameter) and Z, mm


class Plain(msgspec.Struct):
    """The plain block being written: G codes, keywords, words, M codes in the grammar's order."""
    g: list[int] = []
    keywords: list[str] = []
    words: dict[str, str] = {}
    m: list[int] = []
    ends: bool = False

    def text(self) -> str:
        parts = [f"G{code}" for code in self.g] + self.keywords
        parts += [f"{name}={value}" if len(name) > 1 or value.startswith('"') else f"{name}{value}"
                  for name, value in self.words.items()]
        return " ".join(parts + [f"M{code}" for code in self.m] + (["M30"] if self.ends else []))


def number(value: float) -> str:
    """A plain decimal with at most six places (a micrometre's thousandth), no exponent."""
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def plain_block(found: list[Word], state: BlockState, values: dict[str, float]) -> Plain:
    """The plain block of a block's address words (assignments and control words taken out)."""
    plain = Plain()
    arc_centre: dict[str, float] = {}
    was_css = state.css
    for word in found:
        _take(word, plain, state, values, arc_centre)
    _finish_motion(plain, state, arc_centre)
    _frozen_speed(plain, state, was_css)
    return plain


def _frozen_speed(plain: Plain, state: BlockState, was_css: bool) -> None:
    """G97 without S after G96 keeps "the last speed set by G96" ([PGF-2004] §7.13): the r/min at the
    diameter where G96 last set it, which the verifier does not follow. A cut (G1 G2 G3 G33) before an
    S states the speed again is refused; a rapid G0 does not depend on it (reference sinumerik-lathe §S6)."""
    if 97 in plain.g and was_css and "S" not in plain.words:
        state.frozen = True
    elif "S" in plain.words or 96 in plain.g:
        state.frozen = False
    motion = next((code for code in plain.g if code in MOTIONS), None)
    if state.frozen and motion in CUTTING_MOTIONS and {"X", "Z"} & plain.words.keys():
        raise Refused("a cut after G97 without S after G96: the spindle keeps the speed G96 last reached, "
                      "which the verifier cannot know; state the speed with G97 (G97 S…)")


def _take(word: Word, plain: Plain, state: BlockState, values: dict[str, float],
          arc_centre: dict[str, float]) -> None:
    name = word.name
    if name in REFUSED_WORDS:
        raise Refused(REFUSED_WORDS[name])
    if name in NOT_LATHE_AXES:
        raise Refused(f"{name} is no axis of a lathe (X and Z): a milling program is not a turning program")
    if name in DROPPED_WORDS or (word.form == "call" and name in DROPPED_CALLS):
        return
    if word.form == "keyword" and name in DIAMETER_MODES:
        state.diameter = DIAMETER_MODES[name]
        if "DIAMON" not in plain.keywords:
            plain.keywords.append("DIAMON")
        return
    taker = TAKERS.get(name)
    if taker is None or word.form in ("call", "keyword"):
        raise Refused(_unknown(word))
    taker(word, plain, state, values, arc_centre)


def _unknown(word: Word) -> str:
    if word.form == "call":
        return f"{word.name}(…) is not a statement of the 840D lathe expander"
    return f"{word.name}{'=' if word.form == 'equals' else ''}{word.value}: not a word of the 840D lathe expander"


def value_of(word: Word, values: dict[str, float]) -> float:
    """A word's number: `X12.5`, or `X=<expression>` evaluated; AC(…) is absolute, IC(…) refused."""
    if word.form == "number":
        return plain_decimal(word.name, word.value)      # at most MAX_DIGITS digits, never a crash
    text = word.value
    if text.startswith("IC(") or text.startswith("DC(") or text.startswith("CIC("):
        raise Refused(f"{word.name}={text}: an incremental value cannot be verified; program absolute positions")
    if text.startswith("AC(") and text.endswith(")"):
        text = text[3:-1]
    return evaluate(text, values)


def _g(word: Word, plain: Plain, state: BlockState, values: dict[str, float], centre: dict[str, float]) -> None:
    code = int(value_of(word, values))
    code = SAME_AS.get(code, code)
    if code in REFUSED_G:
        raise Refused(REFUSED_G[code])
    if code in MOTIONS:
        state.motion = code
        plain.g.append(code)
    elif code in WORK_OFFSETS:
        _work_offset(code, state.machine)
        plain.g.append(code)
    elif code in KEPT_G:
        plain.g.append(code)
        state.css = {96: True, 97: False}.get(code, state.css)
    elif code not in DROPPED_G:
        raise Refused(f"G{code} is not a G code of the 840D lathe expander")


def _work_offset(code: int, machine: Machine) -> None:
    """Positions are read in the work offset the machine record names, the frame its travel is in."""
    if f"G{code}" != machine.work_offset:
        raise Refused(f"G{code} is not the work offset of machine {machine.name} ({machine.work_offset}), "
                      "in whose frame the travel is stated; set machine.work_offset or program "
                      f"{machine.work_offset}")


def _m(word: Word, plain: Plain, state: BlockState, values: dict[str, float], centre: dict[str, float]) -> None:
    code = int(value_of(word, values))
    if code in END_M:
        plain.ends = True
    elif code in KEPT_M:
        plain.m.append(code)
    elif code not in DROPPED_M:
        raise Refused(f"M{code} is the machine builder's function, not one of the 840D lathe expander "
                      "(M0 M1 M2 M3 M4 M5 M6 M8 M9 M17 M30)")


def _axis(word: Word, plain: Plain, state: BlockState, values: dict[str, float], centre: dict[str, float]) -> None:
    value = value_of(word, values)
    if word.name == "X" and not state.diameter:
        value *= 2.0                 # DIAMOF: X is a radius; the plain block holds a diameter
    plain.words[word.name] = number(value)


def _centre(word: Word, plain: Plain, state: BlockState, values: dict[str, float], centre: dict[str, float]) -> None:
    """I (radius) and K: the arc centre from the start point, AC(…) absolute (X then a diameter);
    in a thread block (G33) K is the lead in mm per turn."""
    if word.name == "K" and _threading(plain, state):
        plain.words["K"] = number(value_of(word, values))
        return
    absolute = word.form == "equals" and word.value.startswith("AC(")
    value = value_of(word, values)
    axis = "X" if word.name == "I" else "Z"
    if absolute:
        centre[axis] = value / 2.0 if axis == "X" and state.diameter else value
        return
    start = state.position.get(axis)
    if start is None:
        raise Refused(f"an arc centre {word.name} from an unknown start point: program X and Z before it")
    centre[axis] = (start / 2.0 if axis == "X" else start) + value


def _threading(plain: Plain, state: BlockState) -> bool:
    return 33 in plain.g or (state.motion == 33 and not set(plain.g) & {0, 1, 2, 3})


def _kept(word: Word, plain: Plain, state: BlockState, values: dict[str, float], centre: dict[str, float]) -> None:
    if word.name == "T" and word.form == "equals" and word.value.startswith('"'):
        if " " in word.value:
            raise Refused(f"T={word.value}: a tool name with a blank; name the tool without one")
        plain.words["T"] = word.value
        return
    value = value_of(word, values)
    if word.name == "S" and 4 in plain.g:
        plain.words["F"] = number(_dwell_seconds(value, state))
        return
    if word.name == "LIMS":
        state.clamp = value
    if word.name == "S":
        state.rpm = None if state.css else value
    plain.words[word.name] = number(value)


def _dwell_seconds(turns: float, state: BlockState) -> float:
    """G4 S…: a dwell of S spindle turns; the plain block says it in seconds (F) at the S in force."""
    if state.css or not state.rpm:
        raise Refused("G4 S… dwells a number of spindle turns: it needs a spindle speed in r/min (G97 S…) "
                      "before it; or dwell in seconds with G4 F…")
    return turns * 60.0 / state.rpm


TAKERS = {"G": _g, "M": _m, "X": _axis, "Z": _axis, "I": _centre, "K": _centre, "F": _kept, "S": _kept,
          "T": _kept, "D": _kept, "CR": _kept, "LIMS": _kept}


def _finish_motion(plain: Plain, state: BlockState, centre: dict[str, float]) -> None:
    if 4 in plain.g:
        return
    moves = bool({"X", "Z"} & plain.words.keys())
    if moves and not set(plain.g) & set(MOTIONS):
        if state.motion is None:
            raise Refused("a move before any G0/G1/G2/G3: program the motion first")
        plain.g.append(state.motion)
    if 96 in plain.g and "LIMS" not in plain.words and state.clamp is not None:
        plain.words["LIMS"] = number(state.clamp)
    if centre:
        plain.words["CR"] = number(_radius_of_centre(plain, state, centre))
    end: dict[str, float] = {axis: float(plain.words[axis]) for axis in ("X", "Z") if axis in plain.words}
    state.position.update(end)


def _radius_of_centre(plain: Plain, state: BlockState, centre: dict[str, float]) -> float:
    """CR of an arc given by its centre: the distance to both ends (which must agree), negative for
    an arc of more than 180° (the 840D's sign of CR)."""
    motion = next((code for code in plain.g if code in (2, 3)), state.motion)
    if motion not in (2, 3) or {"X", "Z"} - state.position.keys():
        raise Refused("I/K without G2/G3 from a known start point")
    start = (state.position["Z"], state.position["X"] / 2.0)
    end = (float(plain.words.get("Z", state.position["Z"])), float(plain.words.get("X", state.position["X"])) / 2.0)
    middle = (centre.get("Z", start[0]), centre.get("X", start[1]))
    radii = [math.hypot(point[0] - middle[0], point[1] - middle[1]) for point in (start, end)]
    if abs(radii[0] - radii[1]) > ARC_TOLERANCE or radii[0] == 0 or start == end:
        raise Refused(f"the arc centre is {radii[0]:.3f} mm from the start and {radii[1]:.3f} mm from the end: "
                      "no arc of one radius joins them")
    sweep = _sweep(start, end, middle, motion == 3)
    return radii[0] if sweep <= math.pi else -radii[0]


def _sweep(start: tuple[float, float], end: tuple[float, float], centre: tuple[float, float], ccw: bool) -> float:
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    return (a1 - a0) % math.tau if ccw else (a0 - a1) % math.tau
