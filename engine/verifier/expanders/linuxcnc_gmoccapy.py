"""gmoccapy's lathe macros as gmoccapy runs them (docs/reference/linuxcnc-lathe.md §7). Every value
below is read from LinuxCNC's sim config configs/sim/gmoccapy/lathe_configs (github.com/LinuxCNC/
linuxcnc at 5c41560, GPL-2.0); nothing is evaluated here, it only writes the program text.

* The Cycles tab (lathe_macros.ini [DISPLAY]EMBED_TAB_COMMAND: gladevcp with lathehandler.py and
  lathemacro.ui) runs a macro when its button fires the EMC_Action_MDI `<tab>.go`: the action's
  `command` with each `${pin}` replaced by the HAL pin's value as "%f" (lib/python/gladevcp/
  hal_actions.py, HalTemplate and FloatComp), sent as ONE MDI line. No preamble file runs: the
  interpreter holds the INI's [RS274NGC]RS274NGC_STARTUP_CODE, run once at task start. In MDI
  nothing ends the call; the verifier ends it with m2 (linuxcnc_callers.with_call).
* A spin box gives the pins `<name>-f` (its value) and `<name>-s` (int() of it), a check or radio
  button the bit `<name>` (gladevcp/hal_widgets.py). The values are savestate.sav's: lathehandler
  restores it at start (gladevcp/persistence.py) when its signature, the sha1 of the widgets'
  names and types, is the .ui's; for the .ui at 5c41560 it is (a9fe768b…, computed from the 64
  widgets). Where the .ui's own value differs (a config started without savestate.sav), UI_VALUES
  gives it.
* The macros read where the tool stands (#<_x> as a radius, #<_z>) after their own `M6 T G43`
  (M6 is remapped to change_g43.ngc: the built-in M6, then G43). gmoccapy writes no position: the
  operator jogs there. Not in the files, so the sim's documented one is taken: the homed position
  ([JOINT_0]HOME = 10 mm, X a radius; [JOINT_1]HOME = -10 mm), G54 zero (the PARAMETER_FILE
  sim.var is not shipped, and LinuxCNC starts all parameters at 0 without it: rs274ngc_pre.cc
  restore_parameters), seen through the macro's tool's offsets in lathe.tbl (program position =
  machine position − offset)."""
from __future__ import annotations

import re

from ..refusals import Refused
from .linuxcnc_callers import with_call

# lathe_macros.ini [RS274NGC]: G8 radius mode and G21 mm until a macro changes them; P0.005 mm
STARTUP_CODE = "G18 G21 G40 G49 G54 G80 G90 G94 G8 M9 M5 G64 P0.005"
HOME_MM = (10.0, -10.0)          # lathe_macros.ini [JOINT_0]HOME (X radius), [JOINT_1]HOME (Z)
# lathe.tbl: tool -> its X (radius) and Z offsets, mm
TOOL_OFFSETS_MM = {1: (-12.0, -25.0), 2: (-10.356, 12.123), 3: (1.123, 25.456), 4: (0.0, 0.0),
                   5: (5.737, 12.2399)}

# macro file -> its tab's widget prefix and the `<prefix>.go` command, verbatim from lathemacro.ui
COMMANDS = {
    "boring": ("bore", "O<boring> call [${bore.x-f}] [${bore.sf-f}] [${bore.cut-f}] [${bore.feed-f}] "
                       "[${bore.z-f}] [${bore.rad-f}] [${bore.angle-f}] [${bore.tool-s}] [${bore.coolant}]"),
    "chamfer": ("chamfer", "O<chamfer>call [${chamfer.x-f}] [${chamfer.sf-f}] [0.5] [0] [${chamfer.z-f}] "
                           "[${chamfer.tool-s}] [0] [${chamfer.size-f}]  [${chamfer.fo}] [${chamfer.fi}] "
                           "[${chamfer.bo}] [${chamfer.coolant}]"),
    "drilling": ("drill", "O<drilling> call [${drill.dia-f}]    [${drill.sf-f}]   [${drill.feed-f}]   "
                          "[${drill.z-f}]   [${drill.peck-f}]   [${drill.tool-s}]   [${drill.coolant}] "),
    "facing": ("face", "O<facing>call [${face.x-f}] [${face.sf-f}] [${face.cut-f}] [${face.feed-f}] "
                       "[${face.z-f}] [${face.angle-s}] [${face.tool-s}] [${face.coolant}] "),
    "grooving": ("groove", "O<grooving> call   [${groove.x-f}]   [${groove.sf-f}]   [${groove.feed-f}]    "
                           "[${groove.tool-s}]   [${groove.coolant}]"),
    "radius": ("radius", "O<radius> call [${radius.x-f}] [${radius.sf-f}] [0.5] [0][${radius.z-f}] "
                         "[${radius.tool-s}] [0] [${radius.rad-f}] [${radius.fo}] [${radius.fi}] "
                         "[${radius.bo}]  [${radius.coolant}]"),
    "threading": ("thread", "O<threading>call [${thread.x-f}] [${thread.sf-f}] [${thread.tool-s}] "
                            "[${thread.pitch-f}] [${thread.z-f}] [${thread.internal}] [${thread.external}]  "
                            "[${thread.coolant}]"),
    "turning": ("turn", "O<turning> call [${turn.x-f}] [${turn.sf-f}] [${turn.cut-f}] [${turn.feed-f}] "
                        "[${turn.z-f}] [${turn.rad-f}] [${turn.angle-f}] [${turn.tool-s}] [${turn.coolant}]"),
}

# savestate.sav [widgets] (mm, m/min, mm/turn, degrees; a tool number; True/False for a button)
SAVED: dict[str, float | bool] = {
    "bore.x": 0.0, "bore.sf": 100.0, "bore.cut": 1.0, "bore.feed": 0.15, "bore.z": 0.0, "bore.rad": 0.0,
    "bore.angle": 0.0, "bore.tool": 1.0, "bore.coolant": True,
    "chamfer.x": 0.0, "chamfer.sf": 100.0, "chamfer.z": 0.0, "chamfer.tool": 1.0, "chamfer.size": 1.0,
    "chamfer.fo": False, "chamfer.fi": False, "chamfer.bo": True, "chamfer.coolant": False,
    "drill.dia": 10.0, "drill.sf": 100.0, "drill.feed": 0.020000000000000004, "drill.z": 0.0,
    "drill.peck": 2.0, "drill.tool": 3.0, "drill.coolant": True,
    # face.sf 0.0: so saved by save_state (the widget's value at exit); FaceSFAdj: lower 100, no value
    "face.x": 0.0, "face.sf": 0.0, "face.cut": 2.8999999999999977, "face.feed": 0.15, "face.z": 0.0,
    "face.angle": 0.0, "face.tool": 1.0, "face.coolant": False,
    "groove.x": 0.0, "groove.sf": 100.0, "groove.feed": 0.03, "groove.tool": 4.0, "groove.coolant": True,
    "radius.x": 0.0, "radius.sf": 100.0, "radius.z": 0.0, "radius.tool": 1.0, "radius.rad": 1.0,
    "radius.fo": False, "radius.fi": True, "radius.bo": False, "radius.coolant": False,
    "thread.x": 6.0, "thread.sf": 60.0, "thread.tool": 5.0, "thread.pitch": 1.0, "thread.z": 0.0,
    "thread.internal": False, "thread.external": True, "thread.coolant": False,
    "turn.x": 15.0, "turn.sf": 60.0, "turn.cut": 1.0, "turn.feed": 0.15, "turn.z": 120.0, "turn.rad": 3.0,
    "turn.angle": 4.0, "turn.tool": 1.0, "turn.coolant": True,
}
# lathemacro.ui's own value where it differs (the adjustment's `value`, 0 if it states none; a
# check button without `active` is off): what a copy of the config without savestate.sav starts with
UI_VALUES: dict[str, float | bool] = {
    "bore.coolant": False, "drill.feed": 0.05, "drill.tool": 1.0, "drill.coolant": False, "face.cut": 1.0,
    "groove.tool": 9.0, "groove.coolant": False, "thread.x": 0.0, "thread.sf": 50.0,
    "turn.sf": 100.0, "turn.z": 0.0, "turn.rad": 0.0, "turn.angle": 0.0, "turn.coolant": False,
}
PIN = re.compile(r"\$\{([-._a-z0-9]+)\}")


def pin_value(pin: str, widgets: dict[str, float | bool]) -> str:
    """A pin as FloatComp gives it: `-f` the value, `-s` its int(), a button's bit 1.0/0.0; "%f"."""
    name, kind = (pin[:-2], pin[-2:]) if pin[-2:] in ("-f", "-s") else (pin, "")
    if name not in widgets:
        raise Refused(f"the pin {pin} is not one of the Cycles tab's widgets")
    value = float(widgets[name])
    return "%f" % (float(int(value)) if kind == "-s" else value)


def mdi_call(name: str, widgets: dict[str, float | bool] = SAVED) -> str:
    """The MDI line the tab sends for the macro file `name` (its `.go` command, pins replaced)."""
    if name not in COMMANDS:
        raise Refused(f"{name}.ngc is not one of gmoccapy's lathe macros")
    return PIN.sub(lambda match: pin_value(match.group(1), widgets), COMMANDS[name][1])


def start_position(name: str, widgets: dict[str, float | bool] = SAVED) -> str:
    """Where the tool stands, in the coordinates the macro reads after its G43 (G8: X a radius)."""
    tool = int(float(widgets[f"{COMMANDS[name][0]}.tool"]))
    if tool not in TOOL_OFFSETS_MM:
        raise Refused(f"T{tool} is not in the sim's tool table lathe.tbl: LinuxCNC refuses its M6")
    x, z = (home - offset for home, offset in zip(HOME_MM, TOOL_OFFSETS_MM[tool]))
    return f"G0 X{x:g} Z{z:g}"


def as_gmoccapy_runs(name: str, lines: list[str], widgets: dict[str, float | bool] = SAVED) -> list[str]:
    """The startup code, the tool where it stands, the file's sub, the tab's MDI call, m2."""
    return with_call(lines, mdi_call(name, widgets), [STARTUP_CODE, start_position(name, widgets)])
