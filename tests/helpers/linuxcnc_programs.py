"""The real LinuxCNC lathe programs of tests/data/nc/linuxcnc and how each is run (issue 27): a
program as it stands, or a subroutine file as the screen that calls it runs it (ngcgui: its
preamble lathe_std.ngc, the file, the call with the form's defaults, m2; a lathe macro: the
preamble, the operator's start position, the call with the MACRODEFAULTS values)."""
from __future__ import annotations

import csv
from pathlib import Path

from engine.machines.records import Machine
from engine.verifier import LimitError, verify_program
from engine.verifier.expanders.linuxcnc_callers import as_called, macro_defaults, ngcgui_defaults

ROOT = Path(__file__).resolve().parent.parent.parent
FOLDER = ROOT / "tests" / "data" / "nc" / "linuxcnc"
SEED = ROOT / "seed_templates" / "machines.csv"
PREAMBLE = (FOLDER / "ngcgui_lathe" / "lathe_std.ngc").read_text().splitlines()   # g18 g20 g40 g49 g90 g94 g54
# The lathe macros turn from where the tool stands (#<_x>, #<_z>): 1.2 in diameter, 0.1 in in front
# of the face, outside the macros' default diameters (1.0 in finish, 1.0 in thread).
MACRO_START = "g7 g0 x1.2 z0.1"
NGCGUI, MACRO = "ngcgui", "macro"


def seeded_lathe() -> Machine:
    with SEED.open(newline="") as handle:
        row = next(row for row in csv.DictReader(handle) if row["name"] == "lathe-linuxcnc")
    numbers = [float(row[c]) if row[c] else None for c in ("x_min", "x_max", "y_min", "y_max", "z_min", "z_max",
                                                             "spindle_max", "table_speed_max", "module_max")]
    return Machine(row["name"], row["kind"], row["dialect"], *numbers)   # type: ignore[arg-type]


LATHE = seeded_lathe()

# The preamble's blend (#<tol> 0.001 in: G64 P0.0254 mm) and the macros' M73 are followed
# (docs/reference/linuxcnc-lathe.md §3, §6).
# The G70-G72 programs are written in radius mode, as rs274 (LinuxCNC's interpreter run alone, whose
# expected output their tests hold) starts, but none states G8: M2 does not reset G7/G8, so their
# first X (the cycle's own) is refused. With G8 and a tool they expand (tests/test_linuxcnc_g7x.py).
X_BEFORE_G7_G8 = "an X before G7/G8: diameter or radius is whatever the last program left"
# file -> (how it runs, None for verified or the construct its refusal names; a called file as its
# screen calls it)
PROGRAMS = {
    "lathe_g70_71_demo.ngc": (None, X_BEFORE_G7_G8),          # on G71.1 X15; with G8, its G42.1 after
    # bare G64 on line 2 (and no tool offset: CAM output with no T, M6 or G43)
    "lathe_pawn.ngc": (None, "G64 without P blends corners without a bound"),
    # M2 does not reset G7/G8 and the INI's startup code runs once (docs/reference §3): not stated
    "lathe-g76.ngc": (None, "G64 without P blends corners without a bound"),   # and an X before G7/G8
    "lathe_g7x_face_boring.ngc": (None, X_BEFORE_G7_G8),      # on G72 X1 in o101; with G8, no S before the cut
    "lathe_g7x_quadrants.ngc": (None, X_BEFORE_G7_G8),        # on G70 X15; with G8, no S before the cut
    # T0 M6 unloads the tool (accepted); the file states no G7/G8, which M2 does not reset
    # line 1 `g20 g64 g18 f30`: LinuxCNC reads F before the line's G20 (order of execution), in
    # the units the last program left (issue 27 lcfix3; before it, the bare G64 of the same line)
    "lathecomp.ngc": (None, "a length before G20/G21"),   # and G64 without P, and an X before G7/G8
    "lathe_macros/boring.ngc": (MACRO, None),
    "lathe_macros/chamfer.ngc": (MACRO, None),
    "lathe_macros/facing.ngc": (MACRO, None),
    "lathe_macros/threading.ngc": (MACRO, None),
    "lathe_macros/turning.ngc": (MACRO, None),
    "lathe_macros/drill.ngc": (MACRO, None),
    # its MACRODEFAULTS are in MACROCOMMAND's order (X, SFM, DOC, Z, Tool, Radius …) but the code
    # reads the tool from #6: called with them, it selects T0.381
    "lathe_macros/radius.ngc": (MACRO, "T0.381 is not a tool"),
    "ngcgui_lathe/od.ngc": (NGCGUI, "G53 moves in machine coordinates: the machine record does not give"),
    "ngcgui_lathe/id.ngc": (NGCGUI, "G53 moves in machine coordinates: the machine record does not give"),
    "ngcgui_lathe/taper-od.ngc": (NGCGUI, "system parameter #5410 holds a value only the control has (the tool "
                                          "table's diameter"),
    "ngcgui_lathe/g76diam.ngc": (NGCGUI, "the file g76base.ngc is not in this program"),
    "ngcgui_lathe/g76base.ngc": (NGCGUI, "#<_vmajor> holds a value only the control has"),
    # LinuxCNC's interpreter tests (tests/interp): its expected output is made in radius mode
    "interp_tests/g71-with-g70.ngc": (None, X_BEFORE_G7_G8),       # on G71.1 X15 (the demo's profile)
    # line 1 `G54 G18 G21 F400`: F is read before the line's G21, in the last program's units
    # (issue 27 lcfix3; before it, the X of G72 X50 before G7/G8, still there after)
    "interp_tests/g72-iterations-present.ngc": (None, "a length before G20/G21"),
    "interp_tests/g72-iterations-missing.ngc": (None, "a length before G20/G21"),
    # G92.1 on line 3 clears the G92 offsets: refused like every G92 code (an offset the verifier
    # does not follow); LinuxCNC ends it (168 lines of expected output, the loop of issue #2939 fixed)
    "interp_tests/g71-endless-loop.ngc": (None, "G92.1 shifts every position by an offset"),
    # no G20/G21 (the F.24 of its G71 line is a length), no G7/G8; LinuxCNC ends it (issue #2844)
    "interp_tests/g71-endless-loop2.ngc": (None, "a length before G20/G21"),
    # G52 shifts Z before its G71 (then g42 before its G70)
    "interp_tests/g71-endless-loop_2.ngc": (None, "G52 shifts every position by an offset"),
    "interp_tests/g76only.ngc": (None, "G64 without P blends corners without a bound"),   # g20 g64 g18
}
# each blends corners (G64 P0.005 in, P0.125 mm) before it reads HAL/INI values or drives M65
PLASMA = {"plasmac_family/imperial_ramp_pierce.ngc": "G64 P0.005 blends corners up to 0.127 mm",
          "plasmac_family/metric_ramp_pierce.ngc": "M65 switches a HAL output",     # its G64 P0.254 after it
          "plasmac_family/imperial_wrench.ngc": "G64 P0.005 blends corners up to 0.127 mm",
          "plasmac_family/metric_wrench.ngc": "G64 P0.125 blends corners up to 0.125 mm"}


def file_lines(name: str) -> list[str]:
    return (FOLDER / name).read_text().splitlines()


def program_of(name: str, values: list[str] | None = None) -> list[str]:
    """The program the control runs for `name`: the file, or the file as its screen calls it."""
    how, _ = PROGRAMS[name]
    lines = file_lines(name)
    if how == NGCGUI:
        return as_called(lines, values or ngcgui_defaults(lines), PREAMBLE)
    if how == MACRO:
        return as_called(lines, values or macro_defaults(lines), [*PREAMBLE, MACRO_START])
    return lines


def refusal(lines: list[str], machine: Machine = LATHE) -> str | None:
    """None for a program the verifier reads whole, else its message."""
    try:
        verify_program(lines, machine, None)
    except LimitError as error:
        return str(error)
    return None
