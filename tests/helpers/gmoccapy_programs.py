"""gmoccapy's lathe macros (tests/data/nc/linuxcnc/gmoccapy_lathe, LinuxCNC's configs/sim/gmoccapy/
lathe_configs) as gmoccapy's Cycles tab runs them, and the two axis lathe macros go_to_position and
probe-hole (issue 27; docs/reference/linuxcnc-lathe.md §7). A table of its own beside PROGRAMS of
helpers.linuxcnc_programs, so the two merge without touching each other."""
from __future__ import annotations

from engine.verifier.expanders.linuxcnc_callers import as_called, macro_defaults
from engine.verifier.expanders.linuxcnc_gmoccapy import SAVED, UI_VALUES, as_gmoccapy_runs
from helpers.linuxcnc_programs import FOLDER, MACRO_START, PREAMBLE

TRAVEL_X = "exceeds the travel of lathe-linuxcnc (X 0"
# macro file -> (its construct as the shipped sim calls it, with savestate.sav's values; the same
# with lathemacro.ui's own values); None: verified. Each refusal is a fault of those values:
GMOCCAPY = {
    # bore.x 0: the finish bore Ø0, so the retract after the last pass goes to X[0 - cut] (Ø-2)
    "boring": (TRAVEL_X, TRAVEL_X),
    # chamfer.x 0 with "back outside": the first pass starts at X[0 - 0.5] (Ø-1)
    "chamfer": (TRAVEL_X, TRAVEL_X),
    # saved: T3's offsets put the start at Z-35.456, so R#<_z> lies below the bottom Z0; the .ui's
    # T1 starts at Z15, above it
    "drilling": ("G83 with R below the bottom Z", None),
    # face.sf 0: G96 S0 (the .ui's FaceSFAdj has lower 100 but no value)
    "facing": ("S0: a spindle speed of 0", "S0: a spindle speed of 0"),
    # the .ui's groove.tool 9 is not in lathe.tbl: no start position, and LinuxCNC refuses the M6
    "grooving": (None, "T9 is not in the sim's tool table lathe.tbl"),
    "radius": (None, None),
    # the .ui's thread.x 0: the truncation pass goes to X[0 - 0.108·pitch]. Saved, it is verified but
    # the turning simulation refuses it on its Ø6 bar: the thread runs from the start Z-22.2399 toward
    # Z0, so G76's first pass rapids into the bar mid-length (tests/test_real_programs_made.py)
    "threading": (None, TRAVEL_X),
    # saved turn.z 120 from the start Z15 at 4°: the taper ends past the axis
    "turning": (TRAVEL_X, None),
}
# the axis lathe macros (`; MACRODEFAULTS=`, called like helpers.linuxcnc_programs' MACRO files):
# as called they are refused today for the preamble's G64 P0.001 only; the outcome below is theirs
# once that bound is accepted, and with `#<tol>` 0.0003 in (0.00762 mm) today
AXIS_MACROS = {
    "lathe_macros/go_to_position.ngc": None,     # G61, M0, then G0 X0 Z0 (the defaults 0.0, 0.0)
    "lathe_macros/probe-hole.ngc": "G38.3 is a probing move",   # and G38.2 in X and Y after it
}


def gmoccapy_lines(name: str) -> list[str]:
    return (FOLDER / "gmoccapy_lathe" / f"{name}.ngc").read_text().splitlines()


def gmoccapy_program(name: str, ui: bool = False) -> list[str]:
    """The program the control runs when the tab's button is pressed (saved values, or the .ui's)."""
    return as_gmoccapy_runs(name, gmoccapy_lines(name), {**SAVED, **UI_VALUES} if ui else SAVED)


def axis_macro(name: str) -> list[str]:
    """An axis lathe macro as called (helpers.linuxcnc_programs' MACRO), the preamble as it stands
    (its G64 P0.001 in, 0.0254 mm, is followed: docs/reference/linuxcnc-lathe.md §3)."""
    lines = (FOLDER / name).read_text().splitlines()
    return as_called(lines, macro_defaults(lines), [*PREAMBLE, MACRO_START])
