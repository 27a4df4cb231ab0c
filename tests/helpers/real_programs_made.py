"""The real lathe programs the verifier accepts (or accepted until a fact of their own stopped
them), each with the stock it is written for, what the turning simulation finds there, and the word
a user would change: the table tests/test_real_programs_made.py runs and
tests/test_real_lathe_share.py counts."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from helpers.gmoccapy_programs import axis_macro, gmoccapy_program
from helpers.linuxcnc_programs import program_of

INCH = 25.4
FANUC0T = Path(__file__).resolve().parent.parent / "data" / "nc" / "fanuc" / "FANUC0T.nc"


def fanuc0t_in_mm() -> list[str]:
    """FANUC0T.nc with the G21 its author relied on the control to be in stated after its O line."""
    lines = FANUC0T.read_text().splitlines()
    return lines[:2] + ["G21"] + lines[2:]


def stock(diameter: float, front: float, back: float) -> dict:
    """A class job's blank (mm): a solid bar, its front face at Z `front`, its back end at `back`."""
    return {"stock_diameter": diameter, "stock_z_front": front, "stock_z_back": back}


# The axis lathe macros start at MACRO_START (g20 g7 g0 x1.2 z0.1): the tool at Ø1.2 in, 0.1 in in
# front of the face. Their defaults finish at Ø1.0 in (#1) over 2 in (#5 = -2): a bar of the start's
# Ø1.2 in, its face at Z0, running on past Z-2 in (-50.8 mm) into the chuck.
MACRO_BAR = stock(1.2 * INCH, 0.0, -100.0)
# gmoccapy's grooving starts beside the bar, G8 X10 Z-10 (Ø20, 10 mm behind the face), changes
# tool there and grooves to #1 = X0 (parts off): the bar lies under the start, Ø18 (1 mm clear on
# the radius; a bar of the start's own Ø20 has the tool change on its surface, inside its envelope).
GROOVING_BAR = stock(18.0, 0.0, -100.0)
# gmoccapy's radius (front inside, #1 = X0, #5 = Z0, radius #8 = 1) starts at G8 X22 Z15 (Ø44,
# 15 mm in front) and feeds each pass out to the start X: a Ø44 bar, its face at Z0 (#5).
RADIUS_BAR = stock(44.0, 0.0, -100.0)
# gmoccapy's threading: an outside M6×1 (#1 = 6, pitch #4 = 1) from its start Z-22.2399 to #5 = Z0:
# a Ø6 bar (the thread's major diameter), its face at Z0.
THREAD_BAR = stock(6.0, 0.0, -100.0)
# FANUC0T rapids to X86. Z0.25 and faces from there out to X118 (its first cut, so the face stands
# at Z0.25), then bores from Ø96 out to Ø107.4 down to Z-51.4: a Ø118 blank, its face at Z0.25, with
# a bore under Ø96 (its first boring pass) that a class job's params cannot state: the solid bar.
FANUC_BLANK = stock(118.0, 0.25, -100.0)

RAPID_THROUGH = "a rapid through material"


@dataclass(frozen=True)
class Real:
    lines: Callable[[], list[str]]
    machine: str
    stock: dict
    refused: tuple[str, str] | None     # the simulation's first finding and its line; None: it passes
    bound: tuple[str, float, float]     # a start (or feed) word: (address, the file's value, a new value)


REAL = {
    "lathe_macros/turning.ngc": Real(lambda: program_of("lathe_macros/turning.ngc"), "lathe-linuxcnc",
                                     MACRO_BAR, None, ("X", 1.2, 1.25)),
    "lathe_macros/chamfer.ngc": Real(lambda: program_of("lathe_macros/chamfer.ngc"), "lathe-linuxcnc",
                                     MACRO_BAR, None, ("X", 1.2, 1.25)),
    "lathe_macros/threading.ngc": Real(lambda: program_of("lathe_macros/threading.ngc"), "lathe-linuxcnc",
                                       MACRO_BAR, None, ("X", 1.2, 1.25)),
    # G83 on the axis pecks into the bar's solid centre
    "lathe_macros/drill.ngc": Real(lambda: program_of("lathe_macros/drill.ngc"), "lathe-linuxcnc",
                                   MACRO_BAR, None, ("X", 1.2, 1.25)),
    # G61, M0, G0 X0 Z0 (its defaults): to the centre of the face, in front of the bar
    "lathe_macros/go_to_position.ngc": Real(lambda: axis_macro("lathe_macros/go_to_position.ngc"),
                                            "lathe-linuxcnc", MACRO_BAR, None, ("X", 1.2, 1.25)),
    # The stock's fault, not the macro's: after its finish pass at #1 (radius) it backs off to
    # X[#1 - #3] and rapids out along Z (G0 Z #13), which is right in a bored blank (a boring bar's
    # body is inside the bore); the class job's blank is solid and the walk clears only the column
    # above the cut, so the retract runs through the core. (As called from Ø1.2 in, above its Ø1.0
    # finish, its roughing loop WHILE [#14 LT [#1 - #3]] never runs: a boring call starts inside.)
    "lathe_macros/boring.ngc": Real(lambda: program_of("lathe_macros/boring.ngc"), "lathe-linuxcnc",
                                    MACRO_BAR, (RAPID_THROUGH, "G0 Z #13"), ("X", 1.2, 1.25)),
    # Not a fault of the stock, nor a crash of the real macro: each pass feeds in to the face
    # diameter #1 at Z#13 (its DOC #3 taken along Z), then G0 Z[#13+#3] back out at #1, along the
    # shoulder it leaves. A real facing tool removes the slab #13…#13+#3 with its edge; the walk
    # clears only a radial feed's own line (an outside tool's body radially above its tip), so the
    # slab stays and the rapid runs through it. Any bar the macro faces (over Ø1.0 in) shows it.
    "lathe_macros/facing.ngc": Real(lambda: program_of("lathe_macros/facing.ngc"), "lathe-linuxcnc",
                                    MACRO_BAR, (RAPID_THROUGH, "G0 Z[#13+#3]"), ("X", 1.2, 1.25)),
    "gmoccapy/grooving": Real(lambda: gmoccapy_program("grooving"), "lathe-linuxcnc", GROOVING_BAR, None,
                              ("X", 10.0, 9.5)),        # G8: the start radius, Ø20 to Ø19
    "gmoccapy/radius": Real(lambda: gmoccapy_program("radius"), "lathe-linuxcnc", RADIUS_BAR, None,
                            ("X", 22.0, 22.5)),         # G8: the start radius, Ø44 to Ø45
    # The program's own fault (its saved values): the thread runs from the start Z-22.2399 toward
    # Z0, so each G76 pass enters the bar at its start, mid-bar, where only the truncation pass's
    # plunge line is cut: its first pass rapids 0.5 mm deep (j1 on the diameter) into the bar.
    "gmoccapy/threading": Real(lambda: gmoccapy_program("threading"), "lathe-linuxcnc", THREAD_BAR,
                                (RAPID_THROUGH, "g76 p#4 z#5 i-1 j1 k#3 h3 r1.5 q29.5 e0 l0"), ("X", 4.263, 4.5)),
    # The stock's fault (no bore in a class job's params): G01Z-51.4 at X96., X95.6, then G00Z0.45
    # back out inside the bore it cut, through the solid core of the bar a class job states.
    # The file states no G20/G21 (it relies on the units the program before it left: refused as it
    # stands, test_iso_lathe_programs.REAL): followed here with G21 stated after its program number.
    "FANUC0T.nc": Real(lambda: fanuc0t_in_mm(), "lathe-fanuc-0t", FANUC_BLANK,
                       (RAPID_THROUGH, "G00Z0.45"), ("F", 0.3, 0.25)),      # F0.3 and F.3
}
MADE = sorted(name for name, real in REAL.items() if real.refused is None)
