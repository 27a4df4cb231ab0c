"""M70–M73: the modal state saved and restored per call level, as LinuxCNC does it
(docs/reference/linuxcnc-lathe.md §6; m-code.adoc M70–M73; src/emc/rs274ngc/interp_convert.cc
`save_settings`, `restore_settings`, `gen_settings`, `gen_m_codes`; interp_o_word.cc
`leave_context`).

M70 saves the modes at the current call level, M73 too and marks them to be restored when the
subroutine returns (`return` or `endsub`; at the main level it only saves), M72 restores them at
the same level (refused without a save there), M71 forgets them. A call starts a level with
nothing saved. The restore changes the expander's modes and writes the plain lines that make the
machine state visible: units first (G20/G21), then F (written " F%.1f" in the restored units: a
feed per turn of 0.004 in comes back as F0), S (" S%.0f"), feed mode, distance, plane, G96/G97,
G90.1/G91.1, G7/G8, G98/G99, G43/G49, path mode, then M3/M4/M5 and the coolant where they differ.
The motion mode, the tool and the position are not restored."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..refusals import Refused
from .linuxcnc_modes import INCH, Modes, coolant

if TYPE_CHECKING:
    from .linuxcnc_modes import Executor

# modes restored as they were saved, with no plain line of their own (each feed block carries its
# feed mode, the plain lines are absolute mm with X a diameter, the blend travels on each line)
RESTORED = ("per_rev", "incremental", "arc_absolute", "diameter", "plane", "blend")


class Contexts:
    """The saved modes of each call level (LinuxCNC `sub_context[call_level]`), 0 the main program.
    `saved` holds a level's modes while CONTEXT_VALID is set; `on_return` the levels whose
    CONTEXT_RESTORE_ON_RETURN is set: M73 in a subroutine sets it and only a new call clears it
    (interp_convert.cc convert_m M70-M73; interp_o_word.cc, `context_status = 0` at the call), so
    an M70 after M73, or M71 then M70, saves anew and the return still restores."""

    def __init__(self) -> None:
        self.level = 0
        self.saved: dict[int, Modes] = {}
        self.on_return: set[int] = set()

    def carry_out(self, executor: Executor, code: int) -> None:
        """M70–M73 in their place of a line's order of execution (after M3/M4/M5, before M7–M9)."""
        if code in (70, 73):
            self.saved[self.level] = executor.modes.copy()
            if code == 73 and self.level > 0:
                self.on_return.add(self.level)
        elif code == 71:
            self.saved.pop(self.level, None)     # clears VALID only: the restore-on-return flag stays
        elif self.level not in self.saved:
            raise Refused("M72 with no modes saved at this call level (no M70/M73, or M71 forgot them): "
                          "LinuxCNC refuses it")
        else:
            restore(executor, self.saved[self.level])

    def enter(self) -> None:
        self.level += 1
        self.saved.pop(self.level, None)
        self.on_return.discard(self.level)

    def leave(self, executor: Executor) -> list[str]:
        """The plain lines of a subroutine's return: the restore when both flags are set
        (interp_o_word.cc leave_context). The lines a block is still writing (a G70-G72 reading
        its profile sub) are kept as they were."""
        pending, executor.out = executor.out, []
        saved = self.saved.pop(self.level, None)
        armed = self.level in self.on_return
        self.on_return.discard(self.level)
        self.level -= 1
        if saved is not None and armed:
            restore(executor, saved)
        restored, executor.out = executor.out, pending
        return restored


def restore(executor: Executor, saved: Modes) -> None:
    modes = executor.modes
    if modes.inch != saved.inch:             # units first, so F is read in the restored units
        modes.inch = saved.inch
        executor.out.append("G21")
    _feed_and_speed(executor, saved)
    if saved.plane == "18" and modes.plane != "18":
        executor.out.append("G18")
    blend = _restored_blend(modes, saved)
    for name in RESTORED:
        setattr(modes, name, getattr(saved, name))
    modes.blend = blend
    if "retract" in saved.extra:
        modes.extra["retract"] = saved.extra["retract"]
    _spindle_and_coolant(executor, saved)
    if saved.offset != modes.offset:
        modes.offset = bool(saved.offset)    # an offset never stated comes back as none: fail closed
        executor.out.append("G43" if modes.offset else "G49")


def _restored_blend(modes: Modes, saved: Modes) -> float:
    """gen_settings writes a changed G64 tolerance as " G64 P%f" in the restored units: six
    decimals, so a P under 0.0000005 comes back as P0.000000, which LinuxCNC reads as no bound."""
    if saved.blend <= 0 or saved.blend == modes.blend:
        return saved.blend
    unit = INCH if saved.inch else 1.0
    printed = float(f"{saved.blend / unit:f}")
    if printed <= 0:
        raise Refused(f"the restore writes the saved G64 P{saved.blend / unit:g} as G64 P{printed:f}: LinuxCNC reads a "
                      "zero tolerance as none, corners blend without a bound; save a P of 0.000001 or more")
    return printed * unit


def _feed_and_speed(executor: Executor, saved: Modes) -> None:
    """F and S always (gen_settings: F%.1f, S%.0f), in the restored units; G96 comes back without D."""
    modes = executor.modes
    feed = float(f"{(saved.feed or 0.0) / (INCH if saved.inch else 1.0):.1f}")
    modes.feed = executor.length(feed) if feed else None
    if saved.css and not modes.css:
        raise Refused("the restore turns G96 back on without its clamp D (LinuxCNC: the spindle speed is then "
                      "not limited near the axis); state G96 D… S… after the call")
    modes.css = saved.css
    modes.speed = float(f"{saved.speed or 0.0:.0f}")
    if saved.spindle != 5 and modes.speed == 0:
        raise Refused(f"the restore turns the spindle on (M{saved.spindle}) at S0: it stands while the program "
                      "cuts; state S above 0 before the M70/M73")
    if modes.speed:
        executor.speed_line()


def _spindle_and_coolant(executor: Executor, saved: Modes) -> None:
    """gen_m_codes: the spindle, then mist (M7, or M9 when neither is on) and flood (M8), each
    where it differs from the state before the restore (an M9 there stops both)."""
    modes = executor.modes
    if saved.spindle != modes.spindle:
        modes.spindle = saved.spindle
        executor.out.append(f"M{saved.spindle}")
    for now, then in zip(_coolant(modes), _coolant(saved)):
        if then != now and then is not None:
            coolant(modes, then)
            executor.out.append(f"M{then}")


def _coolant(modes: Modes) -> tuple[int | None, int | None]:
    """interp_write.cc write_m_codes: mist 7, or 9 when neither is on (None under flood alone); flood 8 or None."""
    return (7 if modes.mist else None if modes.flood else 9), (8 if modes.flood else None)
