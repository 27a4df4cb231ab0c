"""The real lathe programs of other people's repositories (tests/data/nc/linuxcnc_extra,
lathe_easystep, liblathe) and what the verifier says of each: the outcome table
tests/test_real_lathe_corpus.py asserts file by file and tests/test_real_lathe_share.py counts."""
from __future__ import annotations

SOURCES = ("linuxcnc_extra", "lathe_easystep", "liblathe")
RIGHT, GAP = "fail closed is right", "gap"

# Constructs named by the refusals (substrings of the one-line message).
BARE_G64 = "G64 without P blends corners without a bound"
BLOCK_DELETE = "block delete /: whether the line runs is the operator's switch"
NO_Y = "Y0: the lathe has no Y axis"
G83_RETRACT = "G83 before G98/G99: the retract level is whatever the last program left"
NOSE_COMP = "cutter radius compensation: the tool path under compensation is not the programmed one"
NO_OFFSET = "a cut with no tool length offset active"
G53 = "G53 moves in machine coordinates"
TRAVEL_Z300 = "Z300 exceeds the travel of lathe-linuxcnc (Z -600…200)"

# file (under tests/data/nc) -> (machine, None for verified or the construct its refusal names,
# RIGHT or GAP, why)
CORPUS = {
    # LinuxCNC/linuxcnc: lathe files not in tests/data/nc/linuxcnc
    # line 1 `g20 g64 g18 f30`: LinuxCNC reads F before the line's G20 (order of execution), in the
    # units the last program left (issue 27 lcfix3; before it, the bare G64 of the same line)
    "linuxcnc_extra/lathe-comp_test.ngc": (
        "lathe-linuxcnc", "a length before G20/G21", RIGHT,
        "the cutter-comp test: F30 read in the last program's units; bare G64, no G7/G8, a cut with T0"),
    "linuxcnc_extra/axis-lathe.ngc": (
        "lathe-linuxcnc", BLOCK_DELETE, RIGHT,
        "AXIS's splash drawing: behind the / lines no G7/G8, no G18, no tool, no S: not a cutting program"),
    "linuxcnc_extra/g76.ngc": (
        "lathe-linuxcnc", BARE_G64, RIGHT,
        "bare G64 has no path bound; behind it no G7/G8 and G92 Z0 shifts (computable from the position)"),
    "linuxcnc_extra/threading.ngc": (
        "lathe-linuxcnc", BARE_G64, RIGHT,
        "bare G64; behind it no G7/G8, no G18 and no tool selected: it runs whatever tool is loaded"),
    "linuxcnc_extra/bad_spirals_lathe.ngc": (
        "lathe-linuxcnc", BLOCK_DELETE, RIGHT,
        "a trajectory-planner fault case: its G3 centre is 12.7 mm from the start, 25.4 mm from the end"),
    "linuxcnc_extra/g33_blend.ngc": (
        "lathe-linuxcnc", BLOCK_DELETE, RIGHT,
        "a planner test: behind the / line G64 P0.002 in (0.0508 mm) and cuts with no tool offset"),
    "linuxcnc_extra/g33_simple.ngc": (
        "lathe-linuxcnc", BARE_G64, RIGHT,
        "bare G64; behind it no G7/G8, no G18, and G33 with no tool or tool offset"),
    "linuxcnc_extra/millturn_example.ngc": (
        "lathe-linuxcnc", NO_Y, RIGHT,
        "a mill-turn (XYZ+C) demo: G10 L2 work offsets with Y, custom M429: not a two-axis lathe"),
    # peter-pan08/LatheEasyStep: programs its LinuxCNC conversational panel wrote, kept as test files
    # (none states G43 after M6: behind the cycles LinuxCNC would apply no tool offset)
    "lathe_easystep/Test_Bohren.ngc": (
        "lathe-linuxcnc", G83_RETRACT, RIGHT,
        "its G72 facing expands; then a peck drill G83 with no G98/G99 stated (M2 does not reset it)"),
    "lathe_easystep/Test_Gewinde.ngc": (
        "lathe-linuxcnc", NOSE_COMP, GAP,
        "G72 facing expands; then G42.1 D0.8 L2, tool nose radius compensation, which is not modelled"),
    "lathe_easystep/Test_Gewinde_innen.ngc": (
        "lathe-linuxcnc", NO_OFFSET, GAP,
        "its G72 cuts after T01 M6 with no G43 (its panel's M6 remap applies it; the record cannot say so)"),
    "lathe_easystep/Test_Innendrehen_mit_Gewinde.ngc": (
        "lathe-linuxcnc", NOSE_COMP, GAP,
        "the same part as Test_Gewinde_innen with other retract planes: G41.1 nose compensation"),
    "lathe_easystep/test.ngc": (
        "lathe-linuxcnc", G53, GAP,
        "tool change point X70 Z100 in machine coordinates (the record lacks the G54 origin); G72 next"),
    # the same panel's example output of January 2026 (ngc/, removed from the repository later)
    "lathe_easystep/ngc/Abdrehen.ngc": (
        "lathe-linuxcnc", TRAVEL_Z300, RIGHT,
        "tool-change point Z300 beyond the record's Z 200 mm; behind it cuts after M6 with no G43"),
    "lathe_easystep/ngc/Bohren.ngc": (
        "lathe-linuxcnc", G53, GAP,
        "G53 tool-change point; behind it axial drilling G81 at X0, which the lathe model lacks too"),
    "lathe_easystep/ngc/Einstich.ngc": (
        "lathe-linuxcnc", G53, GAP,
        "G53 tool-change point; behind it a groove cut after M6 with no G43 (no tool offset applied)"),
    "lathe_easystep/ngc/Gewinde.ngc": (
        "lathe-linuxcnc", G53, GAP,
        "G53 tool-change point; behind it the G76 thread after M6 with no G43 (no tool offset)"),
    "lathe_easystep/ngc/Planen.ngc": (
        "lathe-linuxcnc", G53, GAP,
        "G53 tool-change point; behind it facing with the profile cycle G72 on a contour subroutine"),
    # dubstar-04/LibLathe: the roughing path its profile operation wrote (FreeCAD's XYZ path model)
    "liblathe/profile.gcode": (
        "lathe-linuxcnc", NO_Y, RIGHT,
        "Y0 in every block and F on G0, no units, no spindle, no tool: a path dump, not a program"),
}
