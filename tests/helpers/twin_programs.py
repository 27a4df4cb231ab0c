"""Reading an 840D and a Fanuc hobbing program of the same gear side by side (issue 30): their moves
(X, Y, Z, A, feeds, dwells, spindle speed), and their couplings as the table's turn per hob turn
and per mm of Z, for comparison with docs/reference/fanuc-egb.md §F4–§F5 computed from the records.
A plain reader of its own, not the engine's: the test must not read the programs through the code
it checks."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

WORD = re.compile(r"(?:^|(?<=\s))([A-Z])=?(-?\d+(?:\.\d*)?|-?\.\d+)(?=\s|$)")
EGON = re.compile(r'EGON\(C,"FINE",B,(-?\d+),(\d+)(?:,([YZ]),(-?[\d.]+),1)?\)')
G81 = re.compile(r"^G81 T(\d+) L(-?\d+)(?: Q(\d+\.\d*) P(-?\d+\.\d*))?$")
MOTION = {"G0": "G0", "G00": "G0", "G1": "G1", "G01": "G1"}
AXES = "XYZA"
NOT_MOVES = {"G25", "G26", "G22"}   # the 840D's working-area limits and Fanuc's stroke check: no motion


@dataclass(frozen=True)
class Coupling:
    """The table's turn: `per_hob` degrees of C per degree of B, `per_z` degrees of C per mm of Z."""
    per_hob: float
    per_z: float


def code_of(line: str, dialect: str) -> str:
    """The line without its comment: `; …` on the 840D, `( … )` on Fanuc; `%` and O numbers are framing."""
    code = line.split(";")[0] if dialect == "840d" else re.sub(r"\([^)]*\)", "", line)
    code = code.strip()
    return "" if code == "%" or re.fullmatch(r"O\d+", code) else code


def moves(lines: list[str], dialect: str) -> list[tuple]:
    """Each block that moves an axis, dwells or sets the spindle: (what, values), in order, with the
    modal G0/G1 carried; dwells in seconds (840D `G4 F`, Fanuc `G04 X`)."""
    found, mode = [], None
    for line in lines:
        code = code_of(line, dialect)
        words = WORD.findall(code) if "(" not in code else []
        g_words = [f"G{value}" for letter, value in words if letter == "G"]
        if {"G4", "G04"} & set(g_words):
            seconds = next(float(v) for letter, v in words if letter == ("F" if dialect == "840d" else "X"))
            found.append(("dwell", seconds))
            continue
        if NOT_MOVES & set(g_words):
            continue
        mode = next((MOTION[g] for g in g_words if g in MOTION), mode)
        axes = {letter: float(v) for letter, v in words if letter in AXES}
        if axes:
            feed = next((float(v) for letter, v in words if letter == "F"), None)
            found.append((mode, tuple(sorted(axes.items())), feed))
        found.extend(("spindle", float(v)) for letter, v in words if letter == "S")
    return found


def couplings_840d(lines: list[str]) -> list[Coupling]:
    """Each EGON of the program (a cluster gear's units each have theirs): numerator/denominator
    per hob turn, the Z factor per mm."""
    found = [EGON.search(line).groups() for line in lines if EGON.search(line)]
    return [Coupling(int(numerator) / int(denominator), float(factor) if axis == "Z" else 0.0)
            for numerator, denominator, axis, factor in found]


def couplings_fanuc(lines: list[str], helix_sign: int) -> list[Coupling]:
    """Each G81 T L Q P read by fanuc-egb.md §F4 (4): the table turns L/T per hob turn, and the
    control's helical compensation adds egb_helix_sign·sin P·360/(π·T·Q) degrees of C per mm of Z."""
    found = [G81.match(code_of(line, "fanuc")).groups() for line in lines if G81.match(code_of(line, "fanuc"))]
    return [Coupling(int(threads) / int(teeth), _compensation(int(teeth), module, angle, helix_sign))
            for teeth, threads, module, angle in found]


def _compensation(teeth: int, module: str | None, angle: str | None, helix_sign: int) -> float:
    if module is None or angle is None:
        return 0.0
    return helix_sign * math.sin(math.radians(float(angle))) * 360 / (math.pi * teeth * float(module))


def reference_coupling(gear: dict, hob: dict, senses: dict) -> Coupling:
    """fanuc-egb.md §F5 in the machine's senses for a gear (or unit) of gear["teeth"] teeth:
    k_B = −h_hob·z0/z2 times c·b, and k_Z = −h_gear·360·sin β/(π·m_n·z2) times c·z (degrees per
    mm; 0 for a spur gear)."""
    h_hob = 1 if hob["hand"] == "R" else -1
    h_gear = 1 if gear["hand"] == "R" else -1
    per_hob = -h_hob * hob["starts"] / gear["teeth"] * senses["c"] * senses["b"]
    beta = math.radians(gear["helix_angle"])
    per_z = -h_gear * 360 * math.sin(beta) / (math.pi * gear["module"] * gear["teeth"]) * senses["c"] * senses["z"]
    return Coupling(per_hob, per_z)


def p_rounding_bound(gear: dict) -> float:
    """The most the Fanuc program's Z term can differ from k_Z by writing P to 0.0001°: half an
    increment times d(k_Z)/dP (degrees per mm)."""
    step = math.radians(0.00005)
    return 360 / (math.pi * gear["module"] * gear["teeth"]) * step + 1e-9
