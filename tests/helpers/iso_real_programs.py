"""The real Fanuc/ISO lathe files of tests/data/nc/fanuc and what the verifier says of each: the
outcome table tests/test_iso_lathe_programs.py asserts file by file and
tests/test_real_lathe_share.py counts."""
from __future__ import annotations

import re

from engine.machines.records import Machine, load_machine
from engine.verifier import LimitError, verify_program
from engine.verifier.expanders.iso import expand_iso

# file -> (the seeded record it runs on, verified, the construct its refusal names). The files are
# as their authors wrote them.
REAL = {
    # Fanuc 0T, written for pocket-calculator decimal input (X86. beside X118 and Z-45, a fact of
    # the lathe-fanuc-0t record) and the control's power-on G18 G40 G97 G99; it states no G20/G21:
    # a Fanuc keeps the units the program before it left (reset and M30 do not clear them), so its
    # X86. is 86 mm only if that program ran in G21 (adversary 27c; migration 0031 took G21 out of
    # the record's power_on). Verified until then; with G21 stated it is (test_real_programs_made)
    "FANUC0T.nc": ("lathe-fanuc-0t", False, "motion before G21 (mm) is stated"),
    # ':0100' program number and custom macro B (#501 … #509, X[#504+6.]) are followed; then
    # N1G0X380.Z300.T0101M16 indexes the turret in a block that moves (whether it indexes during
    # or after the move is the builder's parameter), and past that G96 S250 has no spindle clamp
    # G50 S before it: the spindle speeds up without bound as X nears 0
    "0100.nc": ("lathe-fanuc-0t", False, "T0101 with a move in the same block"),
    # '%O1200' on one line, G-code system B (G90 G95 G92 S500 G33) is followed; it relies on the
    # power-on plane G18, which lathe-iso's record does not state (and past that, its tool calls
    # are comments "(T0101)": a cut with no tool offset, test below)
    "TOKARKA.NC": ("lathe-iso", False, "motion before G18 (the ZX plane of the arcs) is stated"),
    # a lathe program of another control, Philips System 3000 (%PM tape start, G13 N1=8001 N2=8011
    # repeats, G15/G17 contour words A B, G68): not ISO; refused on its first line
    "PHILIPS.nc": ("lathe-iso", False, "'%PM' is not a word of the ISO lathe grammar"),
}


def stored_name(lines: list[str]) -> str:
    """The name the header gives (O1200 (TOKARKA)), the program's name in the shop; TEST if none."""
    named = re.search(r"[O:]\d+\s*\((\w+)\)", "".join(lines[:2]))
    return named.group(1) if named else "TEST"


def verdict(conn, machine: str, lines: list[str]) -> str | None:
    """None if the program is verified, else the refusal (one line)."""
    try:
        verify_program(lines, load_machine(conn, machine), stored_name(lines))
    except LimitError as refused:
        assert "\n" not in str(refused) and str(refused).endswith("nothing stored")
        return str(refused)
    return None


FANUC_0T = "lathe-fanuc-0t"      # pocket-calculator input, power-on G18 G40 G97 G99, system A


def plain_moves(machine: Machine, lines: list[str]) -> list[tuple[float, float]]:
    """(X, Z) of every feed move G1 the expander writes, as absolute mm."""
    moves = []
    for line in expand_iso(lines, machine):
        words = dict(re.findall(r"([XZ])(-?[\d.]+)", line.text))
        if line.text.startswith("G1 ") and "X" in words and "Z" in words:
            moves.append((float(words["X"]), float(words["Z"])))
    return moves


def cut(body: list[str]) -> list[str]:
    return ["%", "O0002", "G21", "G50 S2000", "T0101", "G97 S800 M03", "G00 X122. Z2."] + body + \
        ["G00 X200. Z150.", "M30", "%"]
