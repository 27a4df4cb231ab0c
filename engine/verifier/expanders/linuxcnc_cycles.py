"""LinuxCNC's lathe cycles (docs/reference/linuxcnc-lathe.md §5).

G76 P Z I J K R Q H E L (LinuxCNC gcode G76, src/emc/rs274ngc/interp_convert.cc
convert_threading_cycle): from the drive line (the X and Z the tool stands at) the thread's peak
lies at X + I (I < 0 outside, > 0 inside); pass n cuts J·n^(1/R) beyond the peak, offset along Z
by the compound angle Q, until the full depth K beyond the peak, which is cut once and once more
per spring pass H; the tool ends at the block's X and Z. In G7 I, J and K are diameters. The taper
E/L is refused (not modelled).

G70/G71/G72 (profile cycles over a subroutine Q, with a distance D kept normal to the profile,
pockets and fillets) are engine.verifier.expanders.linuxcnc_g7x's, ported from LinuxCNC's own
interp_g7x.cc: engine.verifier.expanders.cycles offsets a contour by the Fanuc allowances U/W,
which is not LinuxCNC's D, so its moves would not be the control's."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..refusals import Refused
from .cycles import MAX_PASSES, RAPID, THREAD
from .linuxcnc_drilling import drilling
from .linuxcnc_g7x import profile_cycle
from .linuxcnc_modes import number
from .linuxcnc_motion import move, target

if TYPE_CHECKING:
    from .linuxcnc_modes import Executor
    from .linuxcnc_words import Words

CYCLES = frozenset({"76", "70", "71", "71.1", "71.2", "72", "72.1", "72.2"})


def move_or_cycle(executor: Executor, words: Words, motion: str) -> None:
    """The motion of a line: a cycle here, any other motion by linuxcnc_motion.move. A feed with
    no tool in the spindle (T0 M6 unloaded it) is refused: no tool would cut where the program says."""
    if motion not in ("0", "80") and executor.modes.extra.get("loaded") == 0:
        raise Refused(f"G{motion} with no tool in the spindle (T0 M6 unloaded it): change to a tool first")
    if motion in CYCLES:
        cycle(executor, words, motion)
    elif motion == "83":
        drilling(executor, words)
    elif motion == "80":
        if {"x", "z"} & words.values.keys():
            raise Refused("X or Z with G80 (no motion mode): LinuxCNC refuses axis words after G80")
    else:
        move(executor, words, motion)


def cycle(executor: Executor, words: Words, motion: str) -> None:
    if motion != "76":
        profile_cycle(executor, words, motion)
        return
    moves, pitch = threading(executor, words)
    executor.out.extend(_plain(moves, pitch))


def _word(words: Words, letter: str, default: float | None = None) -> float:
    value = words.values.get(letter, default)
    if value is None:
        raise Refused(f"G76 without its {letter.upper()}")
    return value


Pass = tuple[int, float, float]   # (RAPID or THREAD, X diameter, Z), mm


def threading(executor: Executor, words: Words) -> tuple[list[Pass], float]:
    """The passes of rs274ngc convert_threading_cycle, X as a radius: pass at depth d (from the
    drive line) rapids to X + (end − d) outside (− inside) at Z start − zoff, in to X ∓ d, cuts to
    the target Z − zoff, rapids out; zoff = (d − |I|)·tan Q; then to the block's end X/Z."""
    modes = executor.modes
    if modes.x is None or modes.z is None:
        raise Refused("G76 from a position not yet programmed: the drive line is where the tool stands")
    if _word(words, "e", 0.0) > 0 and _word(words, "l", 0.0) != 0:
        raise Refused("G76 with a taper E/L: the taper passes are not modelled; program L0")
    scale = 0.5 if modes.diameter else 1.0
    peak, first, full = (executor.length(_word(words, c)) * scale for c in ("i", "j", "k"))
    pitch = executor.length(_word(words, "p"))
    if peak == 0 or first <= 0 or full <= first or pitch <= 0:
        raise Refused("G76 needs I not 0, J above 0, K above J and P above 0 (LinuxCNC refuses it otherwise)")
    end_x, end_z = target(executor, words)
    assert end_x is not None and end_z is not None
    drive, start_z, inside = modes.x, modes.z, peak > 0
    angle = math.radians(0.0 if _word(words, "q", 0.0) == -1 else _word(words, "q", 0.0))
    angle = -angle if end_z > start_z else angle
    target_z, last = end_z + abs(full) * math.tan(angle), abs(full) + abs(peak)
    side = 1.0 if inside else -1.0
    moves: list[Pass] = []
    for depth in _depths(abs(peak), first, last, _word(words, "r", 1.0), int(_word(words, "h", 0.0))):
        zoff = (depth - abs(peak)) * math.tan(angle)
        back = drive - side * (last - depth)
        moves += [(RAPID, 2 * back, start_z - zoff), (RAPID, 2 * (drive + side * depth), start_z - zoff),
                  (THREAD, 2 * (drive + side * depth), target_z - zoff), (RAPID, 2 * back, target_z - zoff)]
    moves.append((RAPID, 2 * end_x, end_z))
    modes.x, modes.z = end_x, end_z
    return moves, pitch


def _depths(peak: float, first: float, last: float, degression: float, springs: int) -> list[float]:
    """|I| + J·n^(1/R) while short of |K| + |I| (R below 1 counts as 1), then |K| + |I| once and
    once more per spring pass H."""
    degression = max(degression, 1.0)
    depths: list[float] = []
    depth, n = peak + first, 1
    while depth < last:
        depths.append(depth)
        if len(depths) > MAX_PASSES:
            raise Refused(f"G76 makes more than {MAX_PASSES} passes")
        n += 1
        depth = peak + first * n ** (1.0 / degression)
    if springs > MAX_PASSES:
        raise Refused(f"G76 H{springs} asks for more than {MAX_PASSES} spring passes")
    return [*depths, *([last] * (max(springs, 0) + 1))]


def _plain(moves: list[Pass], pitch: float) -> list[str]:
    return [f"G33 X{number(x)} Z{number(z)} K{number(pitch)}" if motion == THREAD else f"G0 X{number(x)} Z{number(z)}"
            for motion, x, z in moves]
