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

# The lathe macros save the modes with M73, restored (the spindle off with them) at their return:
# refused (docs/reference/linuxcnc-lathe.md §5); `adapted` gives them without it (threading.ngc has none).
M73 = "M73 restores the spindle state on return"
# file -> (how it runs, None for verified or the construct its refusal names)
PROGRAMS = {
    "lathe_g70_71_demo.ngc": (None, "profile cycle G71.1"),
    "lathe_pawn.ngc": (None, "no tool length offset active"),
    # M2 does not reset G7/G8 and the INI's startup code runs once (docs/reference §3): not stated
    "lathe-g76.ngc": (None, "an X before G7/G8: diameter or radius is whatever the last program left (M2/M30 keep it"),
    "lathe_g7x_face_boring.ngc": (None, "profile cycle G72"),
    "lathe_g7x_quadrants.ngc": (None, "profile cycle G70"),
    # T0 M6 unloads the tool (accepted); the file states no G7/G8, which M2 does not reset
    "lathecomp.ngc": (None, "an X before G7/G8"),
    "lathe_macros/boring.ngc": (MACRO, M73),
    "lathe_macros/chamfer.ngc": (MACRO, M73),
    "lathe_macros/facing.ngc": (MACRO, M73),
    "lathe_macros/threading.ngc": (MACRO, None),
    "lathe_macros/turning.ngc": (MACRO, M73),
    "lathe_macros/drill.ngc": (MACRO, M73),
    "lathe_macros/radius.ngc": (MACRO, M73),
    "ngcgui_lathe/od.ngc": (NGCGUI, "G53 moves in machine coordinates: the machine record does not give"),
    "ngcgui_lathe/id.ngc": (NGCGUI, "G53 moves in machine coordinates: the machine record does not give"),
    "ngcgui_lathe/taper-od.ngc": (NGCGUI, "system parameter #5410 holds a value only the control has (the tool "
                                          "table's diameter"),
    "ngcgui_lathe/g76diam.ngc": (NGCGUI, "the file g76base.ngc is not in this program"),
    "ngcgui_lathe/g76base.ngc": (NGCGUI, "#<_vmajor> holds a value only the control has"),
}
PLASMA = {"plasmac_family/imperial_ramp_pierce.ngc": "M65 switches a HAL output",
          "plasmac_family/metric_ramp_pierce.ngc": "M65 switches a HAL output",
          "plasmac_family/imperial_wrench.ngc": "is a HAL pin or INI value",
          "plasmac_family/metric_wrench.ngc": "is a HAL pin or INI value"}


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


def adapted(name: str, values: list[str] | None = None) -> list[str]:
    """A lathe macro as a user adapts it for the verifier: called as its screen calls it, without
    the M73 that would restore the modes (and the spindle off) at its return; the m2 after the call
    stops the spindle and coolant anyway."""
    return [line for line in program_of(name, values) if line.split(";")[0].strip().upper() != "M73"]


def refusal(lines: list[str], machine: Machine = LATHE) -> str | None:
    """None for a program the verifier reads whole, else its message."""
    try:
        verify_program(lines, machine, None)
    except LimitError as error:
        return str(error)
    return None
