"""LinuxCNC parameters (docs/reference/linuxcnc-lathe.md §2): numbered `#1`…`#30` are a
subroutine's own (its arguments); in the main program they, like the global `#31`…, hold what the
last program left until the file sets them (a read before is refused); named `#<name>` belong to the
subroutine (or main program) that sets them, `#<_name>` are global; reading a named parameter
never set is an error on the control and is refused here. Of the interpreter's read-only
parameters the position (#<_x>, #<_z>: X as a radius, program units) and the units (#<_imperial>,
#<_metric>) are known; system parameters #5000… and the others hold values only the control has."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import msgspec

from ..refusals import Refused

if TYPE_CHECKING:
    from .linuxcnc_modes import Modes

LOCALS = range(1, 31)
SYSTEM = 5000
# What a machine record would need to hold for a system parameter to be known (none holds it yet)
SYSTEM_NEEDS = {5410: " (the tool table's diameter of the tool in the spindle: the machine record has no "
                      "lathe tool table; program the diameter as a value)"}
INCH = 25.4


class Frame(msgspec.Struct):
    """One subroutine call (or the main program): its parameters and where it returns to."""
    back: int = -1                                      # the line after the call
    numbered: dict[int, float] = {}
    named: dict[str, float] = {}
    counts: dict[int, int] = {}   # repeat loop -> passes left


class Parameters:
    def __init__(self, modes: Modes) -> None:
        self.modes = modes
        self.frames = [Frame()]
        self.numbered: dict[int, float] = {}
        self.named: dict[str, float] = {}

    @property
    def frame(self) -> Frame:
        return self.frames[-1]

    def lookup(self, key: str) -> float:
        if key.isdigit():
            number = int(key)
            if number in LOCALS:
                return self._local(number)
            if number >= SYSTEM and number not in self.numbered:
                raise Refused(f"system parameter #{number} holds a value only the control has"
                              f"{SYSTEM_NEEDS.get(number, '')}")
            if number not in self.numbered:
                raise Refused(f"#{number} is read before the program sets it: a global #31…#4999 keeps what "
                              "the last program or MDI left (LinuxCNC does not clear them between runs); set it first")
            return self.numbered[number]
        found = self._named(key)
        if found is None:
            raise Refused(f"#{key} is read before it is set (LinuxCNC stops there)")
        return found

    def _local(self, number: int) -> float:
        """Inside a call an argument not passed is 0 (interp_read.cc zeroes #N+1…#30 of the call); in
        the main program #1…#30 are plain parameters holding what the last program or MDI left."""
        if len(self.frames) > 1 or number in self.frame.numbered:
            return self.frame.numbered.get(number, 0.0)
        raise Refused(f"#{number} is read in the main program before the program sets it: outside a call "
                      "#1…#30 keep what the last program or MDI left (LinuxCNC clears them only for a call's "
                      "arguments); set it first")

    def defined(self, key: str) -> bool:
        if key.isdigit():
            return True
        try:
            return self._named(key) is not None
        except Refused:
            return False

    def _named(self, key: str) -> float | None:
        if key in READ_ONLY:
            return READ_ONLY[key](self.modes)
        if key.startswith(("<_hal[", "<_ini[")):
            raise Refused(f"#{key} is a HAL pin or INI value: it holds a value only the control has")
        if key.startswith("<_"):
            if key not in self.named and key[2:-1] in CONTROL_ONLY:
                raise Refused(f"#{key} holds a value only the control has")
            return self.named.get(key)
        return self.frame.named.get(key)

    def set(self, key: str, value: float) -> None:
        if key.isdigit():
            number = int(key)
            (self.frame.numbered if number in LOCALS else self.numbered)[number] = value
        elif key in READ_ONLY or (key.startswith("<_") and key[2:-1] in CONTROL_ONLY):
            raise Refused(f"#{key} is read-only")
        else:
            (self.named if key.startswith("<_") else self.frame.named)[key] = value


def _position(axis: str) -> Callable[[Modes], float]:
    def value(modes: Modes) -> float:
        held = modes.x if axis == "x" else modes.z
        if held is None or modes.inch is None:
            raise Refused(f"#<_{axis}> read before the position (and its units) is programmed")
        return held / INCH if modes.inch else held
    return value


def _units(inch: bool) -> Callable[[Modes], float]:
    def value(modes: Modes) -> float:
        if modes.inch is None:
            raise Refused("#<_imperial>/#<_metric> read before G20/G21: the units are the last program's")
        return 1.0 if modes.inch == inch else 0.0
    return value


READ_ONLY = {"<_x>": _position("x"), "<_z>": _position("z"), "<_imperial>": _units(True), "<_metric>": _units(False)}
CONTROL_ONLY = frozenset({
    "line", "motion_mode", "plane", "ccomp", "absolute", "incremental", "inverse_time", "units_per_minute",
    "units_per_rev", "coord_system", "tool_offset", "retract_r_plane", "retract_old_z", "spindle_rpm_mode",
    "spindle_css_mode", "ijk_absolute_mode", "lathe_diameter_mode", "lathe_radius_mode", "spindle_on",
    "spindle_cw", "mist", "flood", "speed_override", "feed_override", "adaptive_feed", "feed_hold", "feed", "rpm",
    "current_tool", "current_pocket", "selected_pocket", "selected_tool", "y", "a", "b", "c", "u", "v", "w",
    "abs_x", "abs_y", "abs_z", "abs_a", "abs_b", "abs_c", "abs_u", "abs_v", "abs_w", "value", "value_returned",
    "task", "call_level", "remap_level", "vmajor", "vminor"})
