"""LinuxCNC's lathe profile cycles G70, G71, G71.1, G71.2, G72, G72.1, G72.2 as the plain moves
the control makes (docs/reference/linuxcnc-lathe.md §5; LinuxCNC docs/src/gcode/g-code.adoc
"G70 Lathe finishing cycle", "G71 G72 Lathe roughing cycles"; Interp::convert_g7x in
src/emc/rs274ngc/interp_g7x.cc, `cc NNN` its line, LinuxCNC/linuxcnc 5c41560e, GPL-2.0).

`G7x Q- <X-> <Z-> <D-> <I-> <R-> <U-> <W->` / `G70 Q- <X-> <Z-> <D-> <E-> <P->`: a rapid to X/Z
(cc 1046), then the lines of the subroutine oQ are read, not run: o-words and parameter settings
are carried out, each G0/G1/G2/G3 (G0 as G1) adds a segment from the last point, U/W add to X/Z
(U halved in G7), A/C put a fillet/chamfer at the line's end, anything else is ignored (cc 1056-
1184). D, E, I, R, U, W are lengths not halved by G7 (a radius); defaults D0 E0 I1 R0.5 P1
(cc 1188). The moves (engine.verifier.expanders.linuxcnc_g7x_path) are G0 for LinuxCNC's
straight_rapid, G1 at the modal F for straight_move, G2/G3 for circular_move (cc 921-968); the
motion mode left is that of the last move. Every G7X error of LinuxCNC is a refusal naming it.

interp_g7x.cc works in program units, its tolerances too (1e-6, monotonic 1e-3, a connecting arc
over a 1e-2 gap, cc 43, 65, 867): the cycle is computed here in the program's units (inches under
G20) and its moves converted to mm only when written as plain lines."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..refusals import Refused
from .linuxcnc_g7x_path import MAX_PASSES, Profile
from .linuxcnc_g7x_segments import Chamfer, Fillet, G7xError, Round, Segment, Straight
from .linuxcnc_modes import INCH, MOTIONS, number
from .linuxcnc_motion import ARC_TOLERANCE_MM, feed_words, signed_radius, target

if TYPE_CHECKING:
    from .linuxcnc_modes import Executor
    from .linuxcnc_words import Words

# LinuxCNC's error texts (cc) and what they mean for the program
MEANINGS = {"Not monotonic": "the profile is not monotone (G71 in Z, G72 in X; a type 1 cycle cannot cut a "
                             "pocket, and a fillet A too large turns it back)"}


def profile_cycle(executor: Executor, words: Words, motion: str) -> None:
    """Carry out a G70/G71/G72 line: its moves are appended to executor.out."""
    modes = executor.modes
    if "q" not in words.values:
        raise Refused(f"G{motion} without its Q (LinuxCNC: G7x.x requires a Q word): the profile's subroutine")
    if modes.plane != "18":
        raise Refused(f"G{motion} outside the ZX plane (LinuxCNC: G7x can only be used in XZ plane (G18))")
    if executor.profile is None:
        raise Refused(f"G{motion}: no program to read the profile's subroutine from")
    x, z = target(executor, words)
    if x is None or z is None:
        raise Refused(f"G{motion} from a position not yet programmed: the cycle starts where the tool stands")
    executor.out.append(f"G0 X{number(2 * x)} Z{number(z)}")
    modes.x, modes.z = x, z
    unit = INCH if modes.inch else 1.0       # target() above refused a length before G20/G21
    reader = ProfileReader(executor, complex(z, x) / unit, unit)
    executor.profile(str(int(words.values["q"])), reader.line)
    if len(reader.path) <= 1:
        raise Refused(f"G{motion} Q{words.values['q']:g}: the profile has fewer than 2 moves; LinuxCNC then cuts "
                      "nothing and holds the profile's end as the position while the tool stands at the start")
    moves = Moves(complex(z, x) / unit)
    try:
        _cut(executor, words, motion, reader, moves)
    except G7xError as error:
        meaning = MEANINGS.get(str(error), "")
        raise Refused(f"G{motion}: LinuxCNC stops with \"G7X error: {error}\"{': ' if meaning else ''}{meaning}") \
            from None
    executor.out.extend(moves.plain(executor, unit))
    modes.x, modes.z, modes.motion = moves.at.imag * unit, moves.at.real * unit, moves.last


def _cut(executor: Executor, words: Words, motion: str, reader: ProfileReader, moves: Moves) -> None:
    """cc 1188-1232: the words and the cycle; a profile ending short of X (G71) or Z (G72) closes
    back to it. D, E, I, R, U, W as written: program units, as the profile."""
    cycle, subcycle = motion.partition(".")[0], int(motion.partition(".")[2] or 0)
    d, e, i, r, u, w = (words.values.get(letter, default)
                        for letter, default in (("d", 0.0), ("e", 0.0), ("i", 1.0), ("r", 0.5), ("u", 0.0),
                                                ("w", 0.0)))
    passes = int(words.values.get("p", 1))
    if i <= 0:
        raise Refused(f"G{motion} I{i:g}: LinuxCNC stops with \"G7X error: I must be greater than zero.\"")
    if passes > MAX_PASSES:
        raise Refused(f"G{motion} P{passes}: more than {MAX_PASSES:,} finishing passes")
    path, end, start = reader.path, reader.at, moves.at
    front, back = path[0].end - path[0].start, path[-1].end - path[-1].start
    if cycle == "70":
        path.finishing(moves, start, (d, e), passes)
        return
    if cycle == "71" and abs(back.real) > 0 and front.imag * (start.imag - end.imag) < 0:
        path.append(Straight(end, complex(end.real, start.imag)))
    if cycle == "72" and abs(back.imag) > 0 and front.real * (start.real - end.real) < 0:
        path.append(Straight(end, complex(start.real, end.imag)))
    path.roughing(moves, subcycle, start, (u, w, d, i, r), rotated=cycle == "72")


class ProfileReader:
    """The profile as convert_g7x builds it from the subroutine's lines (cc 1056-1184)."""

    def __init__(self, executor: Executor, start: complex, unit: float) -> None:
        self.executor, self.at, self.motion = executor, start, "0"     # the cycle's G0 set the mode (cc 1046)
        self.unit = unit             # mm per program unit: the profile is kept in program units
        self.path = Profile()

    def line(self, words: Words) -> None:
        modes = self.executor.modes
        motion = words.g(*MOTIONS)
        self.motion = motion if motion is not None else self.motion
        end = self._end(words)
        if end == self.at:
            return
        if self.motion in ("0", "1"):
            self.path.append(Straight(self.at, end))
        elif self.motion in ("2", "3"):
            self.path.append(Round(self.motion == "3", self.at, self._center(words, end), end))
        if self.motion in ("0", "1", "2", "3"):
            self.path.extend(self._corner(words, end))
        self.at = end
        modes.x, modes.z = end.imag * self.unit, end.real * self.unit    # #<_x>, #<_z>: the profile's point (cc 1179)

    def _end(self, words: Words) -> complex:
        """X/Z as a move reads them, U (halved in G7)/W added in absolute mode only (cc 1072-1103)."""
        modes, values = self.executor.modes, words.values
        x, z = target(self.executor, words)
        assert x is not None and z is not None
        for letter, axis in (("u", "x"), ("w", "z")):
            if letter in values and modes.incremental:
                raise Refused(f"LinuxCNC: G7x error: Cannot use {letter.upper()} in incremental mode (G91)")
            if letter in values and axis in values:
                raise Refused(f"LinuxCNC: G7x error: Cannot use {letter.upper()} and {axis.upper()} in the same block")
        if "u" in values:
            x += self.executor.length(values["u"]) / (2.0 if modes.diameter else 1.0)
        if "w" in values:
            z += self.executor.length(values["w"])
        return complex(z, x) / self.unit

    def _center(self, words: Words, end: complex) -> complex:
        """cc 1117-1156: from R (the centre on the side G2/G3 turns), or I/K from the start
        (G91.1) or absolute (G90.1); LinuxCNC checks the I/K arc as any arc."""
        values, length = words.values, self.executor.length
        start, end = self.at * self.unit, end * self.unit          # the centre found in mm
        if "r" in values:
            if "i" in values or "k" in values:
                raise Refused("LinuxCNC: G7X error: both R and I or K flag used for arc")
            r, chord = length(values["r"]), abs(end - start) ** 2
            if r * r < chord / 4:
                raise Refused(f"an arc R{values['r']:g} shorter than half its chord in the profile")
            side = 1j * math.sqrt((r * r - chord / 4) / chord) * (end - start)
            return ((start + end) / 2.0 + (side if self.motion == "3" else -side)) / self.unit
        if "i" not in values and "k" not in values:
            raise Refused("LinuxCNC: G7X error: either I or K must be present for arc")
        center = complex(length(values.get("k", 0.0)), length(values.get("i", 0.0)))
        center = center if self.executor.modes.arc_absolute else center + start
        if abs(abs(start - center) - abs(end - center)) > ARC_TOLERANCE_MM:
            raise Refused(f"the profile's arc has its centre {abs(start - center):.4f} mm from its start but "
                          f"{abs(end - center):.4f} mm from its end (LinuxCNC allows 0.028 mm)")
        return center / self.unit

    def _corner(self, words: Words, end: complex) -> list[Segment]:
        values = words.values
        if "a" in values and "c" in values:
            raise Refused("LinuxCNC: G7X error: Both A and C parameters on a corner")
        if "a" in values:
            return [Fillet(values["a"], end)]
        if "c" in values:
            return [Chamfer(values["c"], end)]
        return []


class Moves:
    """motion_machine (cc 921): the moves in program coordinates and units, X a radius; an arc ending where
    the tool stands is not made (cc 960)."""

    def __init__(self, at: complex) -> None:
        self.at, self.last = at, "0"
        self.made: list[tuple[str, complex, complex, complex | None]] = []   # motion, from, to, centre

    def straight_move(self, end: complex) -> None:
        self._add("1", end, None)

    def straight_rapid(self, end: complex) -> None:
        self._add("0", end, None)

    def circular_move(self, ccw: bool, center: complex, end: complex) -> None:
        if abs(self.at.real - end.real) >= 1e-6 or abs(self.at.imag - end.imag) >= 1e-6:
            self._add("3" if ccw else "2", end, center)

    def _add(self, motion: str, end: complex, center: complex | None) -> None:
        self.made.append((motion, self.at, end, center))
        self.at, self.last = end, motion

    def plain(self, executor: Executor, unit: float) -> list[str]:
        """The moves as plain lines in mm (`unit` mm per program unit)."""
        return [_plain(executor, motion, start * unit, end * unit, None if center is None else center * unit)
                for motion, start, end, center in self.made]


def _plain(executor: Executor, motion: str, start: complex, end: complex, center: complex | None) -> str:
    axes = f"X{number(2 * end.imag)} Z{number(end.real)}"
    if center is None:
        return f"G0 {axes}" if motion == "0" else f"G1 {axes}{feed_words(executor)}"
    radii = abs(start - center), abs(end - center)
    if abs(radii[0] - radii[1]) > ARC_TOLERANCE_MM:
        raise Refused(f"the cycle's arc has its centre {radii[0]:.4f} mm from its start but {radii[1]:.4f} mm from "
                      "its end: LinuxCNC refuses it (it allows 0.028 mm)")
    radius = signed_radius(sum(radii) / 2, (start.real, start.imag), (end.real, end.imag), (center.real, center.imag),
                           motion == "3")
    return f"G{motion} {axes} R{number(radius)}{feed_words(executor)}"
