"""One LinuxCNC line's words carried out in LinuxCNC's order of execution (docs/reference/
linuxcnc-lathe.md §3) into plain lines of the LinuxCNC lathe grammar: absolute positions in mm,
X a diameter, one motion per block with its G code, a feed block with its feed mode and F.

The modes the program states are followed: G20/G21 (a length in inches is × 25.4), G7/G8 (X a
diameter or a radius), G90/G91 (an incremental X/Z is added to the position), G90.1/G91.1 (arc
centres I/K absolute or from the start), G94/G95 (F per minute or per revolution), G96 with its
clamp D (the plain S is the clamp: the speed the spindle reaches at the axis) and G97, G61/G64 P
(the blend tolerance each plain line carries), G43/G49, and the spindle, S and coolant that M70–M73
save and restore (linuxcnc_context). The start
is the state M2/M30 leaves (LinuxCNC M2/M30: G54, G17, G90, G94, G40, M5, M9, motion G1);
units and diameter mode are not reset by M2, so a length before G20/G21 and an X before G7/G8
are refused: they are whatever the last program left."""
from __future__ import annotations

from collections.abc import Callable

import msgspec
from msgspec.structs import replace

from ..refusals import Refused
from .linuxcnc_words import Words

INCH = 25.4
# G codes refused, and why (a code not here and not carried out below is refused as unknown)
REFUSED = {
    **{code: "cutter radius compensation: the tool path under compensation is not the programmed one; "
             "program the tool tip path (G40)" for code in ("41", "42", "41.1", "42.1")},
    **{code: f"G{code} moves by way of a home position the machine record does not name"
       for code in ("28", "28.1", "30", "30.1")},
    "53": "G53 moves in machine coordinates: the machine record does not give where the work "
          "offset's zero lies in them (a G54 origin X/Z in machine coordinates would); program the "
          "move in work coordinates",
    **{code: f"G{code} selects a work offset the verifier cannot see (positions are read in G54)"
       for code in ("55", "56", "57", "58", "59", "59.1", "59.2", "59.3")},
    **{code: f"G{code} shifts every position by an offset the verifier cannot see"
       for code in ("92", "92.1", "92.2", "92.3", "10", "52")},
    "93": "G93 inverse-time feed: program F per minute (G94) or per revolution (G95)",
    **{code: f"G{code} is a drilling cycle without a lathe model here; program its moves"
       for code in ("73", "74", "81", "82", "84", "85", "86", "87", "88", "89")},
    **{code: f"G{code} is a probing move: where it stops is found on the machine"
       for code in ("38.2", "38.3", "38.4", "38.5")},
    "33.1": "G33.1 rigid tapping is not modelled; program the moves",
    "43.1": "G43.1 dynamic tool offset: use G43 with the tool table",
    "43.2": "G43.2 adds offsets the verifier cannot see",
}
IGNORED_G = frozenset({"54", "18"})   # no position changes
# G64 P<tolerance> keeps the path within P of the programmed one (g-code.adoc G64): the tolerance in
# effect travels with each plain line (PlainLine.blend, mm) to the turning simulation, which lets a
# move be anywhere within it; accepted up to 0.001 in (0.0254 mm), the P LinuxCNC's lathe screens use
BLEND_TOLERANCE = 0.0254
MOTIONS = ("0", "1", "2", "3", "33", "76", "80", "83", "70", "71", "71.1", "71.2", "72", "72.1", "72.2")
IGNORED_M = frozenset({0, 1, 48, 49, 50, 51, 52, 53, 60})      # pauses and override switches
CONTEXT_M = frozenset({70, 71, 72, 73})     # save, forget, restore the modes (linuxcnc_context)
PLAIN_M = frozenset({3, 4, 5, 7, 8, 9})


class Modes(msgspec.Struct):
    """The modal state of the interpreter as LinuxCNC keeps it, lengths in mm and X a radius."""
    inch: bool | None = None            # None: units not stated
    diameter: bool | None = None        # None: G7/G8 not stated
    incremental: bool = False
    arc_absolute: bool = False          # G90.1; LinuxCNC's default is G91.1
    per_rev: bool = False
    plane: str = "17"
    motion: str = "1"
    feed: float | None = None           # mm/min or mm/rev
    css_clamp: float | None = None      # G96 D, r/min
    css: bool = False
    tool: int | None = None             # selected by T, changed by M6
    spindle: int = 5                    # M3, M4 or M5 (M2/M30 leave M5)
    speed: float | None = None          # S as written (r/min, or the G96 surface speed); None: never set
    mist: bool = False                  # M7 (M2/M30 leave M9)
    flood: bool = False                 # M8
    offset: bool | None = None          # G43 active (G49: False); None: not stated
    blend: float = 0.0                  # G64 P in mm; 0 under G61/G61.1
    x: float | None = None              # radius, mm
    z: float | None = None
    extra: dict[str, float] = {}

    def copy(self) -> Modes:
        return replace(self, extra=dict(self.extra))


class Executor:
    """Turns each line's words into plain lines; `modes` is the interpreter's state."""

    def __init__(self, mover: Callable[[Executor, Words, str], None],
                 context: Callable[[Executor, int], None]) -> None:
        self.modes = Modes()
        self.out: list[str] = []
        self.mover = mover       # linuxcnc_motion.move, or a cycle (engine.verifier.expanders.linuxcnc)
        self.context = context   # M70-M73 (engine.verifier.expanders.linuxcnc_context)
        # the interpreter's reader of a G70-G72 profile: the sub's label, what to do with each line's words
        self.profile: Callable[[str, Callable[[Words], None]], None] | None = None

    def run(self, words: Words) -> list[str]:
        self.out = []
        self._check_codes(words)
        for step in STEPS:
            step(self, words)
        return self.out

    def length(self, value: float) -> float:
        if self.modes.inch is None:
            raise Refused("a length before G20/G21: the units are whatever the last program left")
        return value * INCH if self.modes.inch else value

    def _check_codes(self, words: Words) -> None:
        for code in words.codes["g"]:
            name = f"{code:g}"
            if name in REFUSED:
                raise Refused(f"G{name}: {REFUSED[name]}")
            if name not in KNOWN_G:
                raise Refused(f"G{name} is not a G code of the LinuxCNC lathe grammar")
        for code in words.codes["m"]:
            if 62 <= code <= 68:
                raise Refused(f"M{code:g} switches a HAL output (a plasma torch, a probe, a machine's I/O): "
                              "what it drives is not a lathe move the verifier can follow")
            if code not in PLAIN_M | IGNORED_M | CONTEXT_M | {2, 30, 6} or code != int(code):
                raise Refused(f"M{code:g} is not an M code of the LinuxCNC lathe grammar (user M100-M199 "
                              "and I/O codes run what the verifier cannot see)")

    def _feed_mode(self, words: Words) -> None:
        if words.g("93"):
            raise Refused(REFUSED["93"])
        mode = words.g("94", "95")
        if mode is not None:         # interp_convert.cc convert_feed_mode: G94/G95 also set the feed to 0
            self.modes.per_rev, self.modes.feed = mode == "95", None

    def _feed(self, words: Words) -> None:
        if "f" in words.values:
            self.modes.feed = self.length(words.values["f"])

    def _speed(self, words: Words) -> None:
        mode = words.g("96", "97")
        if mode == "96":
            clamp = words.values.get("d")
            if clamp is None or clamp <= 0:
                raise Refused("G96 without a speed clamp D: the spindle would race as X nears the axis; "
                              "write G96 D<max r/min> S…")
            self.modes.css, self.modes.css_clamp = True, clamp
        elif mode == "97":
            self.modes.css = False
        if "s" in words.values:
            speed = words.values["s"]
            if speed <= 0:
                raise Refused(f"S{speed:g}: a spindle speed of 0 (under G96 a surface speed of 0, 0 r/min at any X) "
                              "stops the spindle while M3/M4 stays on, and a cut after it meets a standing bar; "
                              "stop the spindle with M5 and state S above 0")
            self.modes.speed = speed
            self.speed_line()
        elif mode == "96":
            raise Refused("G96 without its S (surface speed)")

    def speed_line(self) -> None:
        """The plain S line of the speed in force: under G96 the clamp, the speed reached at the axis."""
        if self.modes.css:
            assert self.modes.css_clamp is not None
            self.out.append(f"G96 S{_number(self.modes.css_clamp)}")
        else:
            self.out.append(f"G97 S{_number(self.modes.speed or 0)}")

    def _tool(self, words: Words) -> None:
        if "t" in words.values:
            tool = words.values["t"]
            if tool != int(tool) or not 0 <= tool <= 99:
                raise Refused(f"T{tool:g} is not a tool 0 … 99")
            self.modes.tool = int(tool)
        if words.has_m(6):
            if self.modes.tool is None:
                raise Refused("M6 with no tool selected (no T before it)")
            self.modes.extra["loaded"] = float(self.modes.tool)     # T0 M6 unloads (LinuxCNC: tool 0 = none)
            self.out.append(f"T{self.modes.tool} M6")

    def _spindle(self, words: Words) -> None:
        chosen = [int(code) for code in words.codes["m"] if code in (3, 4, 5)]
        if chosen:
            if self.modes.speed == 0 and chosen[-1] != 5:
                raise Refused(f"M{chosen[-1]} with S0 in force (an M72/M73 restore set S0): the spindle stands "
                              "while the program cuts; state S above 0 first")
            self.modes.spindle = chosen[-1]
            self.out.append(" ".join(f"M{code}" for code in chosen))

    def _context(self, words: Words) -> None:
        for code in sorted(CONTEXT_M):
            if words.has_m(code):
                self.context(self, code)

    def _coolant(self, words: Words) -> None:
        chosen = [int(code) for code in words.codes["m"] if code in (7, 8, 9)]
        for code in chosen:
            coolant(self.modes, code)
        if chosen:
            self.out.append(" ".join(f"M{code}" for code in chosen))

    def _lengths_and_planes(self, words: Words) -> None:
        plane = words.g("17", "18", "19")
        if plane is not None:
            self.modes.plane = plane          # only G18 holds the lathe's arcs (linuxcnc_motion)
            if plane == "18":
                self.out.append("G18")
        units = words.g("20", "21")
        if units is not None:
            if self.modes.per_rev and self.modes.inch != (units == "20"):
                # emccanon.cc keeps a G95 rate as written (SET_FEED_RATE) and re-sends it after each
                # traverse in the units then in force (START_SPEED_FEED_SYNCH): no F until stated again
                self.modes.feed = None
            self.modes.inch = units == "20"
            self.out.append("G21")
        diameter = words.g("7", "8")
        if diameter is not None:
            if (diameter == "7") != self.modes.diameter and self._motion_to_be(words) == "76":
                raise Refused(f"G{diameter} on a G76 line that switches the diameter mode: LinuxCNC rescales I, J, "
                              "K once more (interp_convert.cc convert_lathe_diameter_mode, G76 ×2 or ÷2 again): "
                              "the thread's depth is not the one written; state G7/G8 on a line of its own")
            self.modes.diameter = diameter == "7"

    def _motion_to_be(self, words: Words) -> str | None:
        """LinuxCNC's block->motion_to_be: the line's motion code, or the modal one when axes are written."""
        motion = words.g(*MOTIONS)
        return motion if motion is not None or not {"x", "z"} & words.values.keys() else self.modes.motion

    def _offsets(self, words: Words) -> None:
        if words.g("40"):
            self.out.append("G40")
        if words.g("43"):
            holder = words.values.get("h")
            if holder is not None and holder != self.modes.tool:
                raise Refused(f"G43 H{holder:g} applies another tool's length than the one in the spindle")
            self.modes.offset = True
            self.out.append("G43")
        if words.g("49"):
            self.modes.offset = False
            self.out.append("G49")

    def _path_mode(self, words: Words) -> None:
        if words.g("61", "61.1"):
            self.modes.blend = 0.0
        if not words.g("64"):
            return
        tolerance = words.values.get("p")
        if tolerance is None:
            raise Refused("G64 without P blends corners without a bound (as fast as possible, rapids too): "
                          f"write G61, or G64 P<tolerance> of {BLEND_TOLERANCE:g} mm (0.001 in) or less")
        if tolerance <= 0:      # interp_convert.cc convert_control_mode: P < 0 is the default tolerance, 0
            raise Refused(f"G64 P{tolerance:g}: LinuxCNC reads a zero or negative tolerance as none (tc.c "
                          "tcFindBlendTolerance: a quarter of each move), corners blend without a bound: write "
                          f"G61, or G64 P<tolerance> above 0 and up to {BLEND_TOLERANCE:g} mm (0.001 in)")
        if self.length(tolerance) > BLEND_TOLERANCE + 1e-9:     # 0.001 in × 25.4 in floating point
            raise Refused(f"G64 P{tolerance:g} blends corners up to {self.length(tolerance):g} mm off the programmed "
                          f"path, more than the {BLEND_TOLERANCE:g} mm (0.001 in) the proof allows for: write G61, "
                          "or a smaller P")
        self.modes.blend = self.length(tolerance)

    def _distance(self, words: Words) -> None:
        distance = words.g("90", "91")
        if distance is not None:
            self.modes.incremental = distance == "91"
        retract = words.g("98", "99")
        if retract is not None:              # a canned cycle's retract: initial level (G98) or R (G99)
            self.modes.extra["retract"] = float(retract)
        arcs = words.g("90.1", "91.1")
        if arcs is not None:
            self.modes.arc_absolute = arcs == "90.1"

    def _motion(self, words: Words) -> None:
        motion = words.g(*MOTIONS)
        if motion is not None:
            if motion != self.modes.motion:
                self.modes.extra.pop("cycle_il", None)     # a new motion mode ends the cycle's initial level
            self.modes.motion = motion
        if motion is not None or {"x", "z"} & words.values.keys():
            self.mover(self, words, self.modes.motion)

    def _stop(self, words: Words) -> None:
        for code in (2, 30):
            if words.has_m(code):
                self.out.append(f"M{code}")


def _number(value: float) -> str:
    """A plain decimal with its point, to 0.1 µm (finer than any control's increment)."""
    text = f"{value:.4f}".rstrip("0")
    return "0." if text in ("-0.", "0.") else text


number = _number


# M7 turns mist on, M8 flood, M9 both off: (mist, flood) after it, None where it is left as it was
COOLANT: dict[int, tuple[bool | None, bool | None]] = {7: (True, None), 8: (None, True), 9: (False, False)}


def coolant(modes: Modes, code: int) -> None:
    mist, flood = COOLANT[code]
    modes.mist = modes.mist if mist is None else mist
    modes.flood = modes.flood if flood is None else flood


KNOWN_G = frozenset({*MOTIONS, *IGNORED_G, "61", "61.1", "64", "98", "99", "4", "17", "19", "7", "8", "20", "21",
                     "40", "43", "49", "90", "91", "90.1", "91.1", "94", "95", "96", "97"})
# LinuxCNC's order of execution of a line's items (overview.adoc "G-code Order of Execution";
# interp_execute.cc execute_block: spindle mode, feed mode, F, S, T, convert_m, convert_g, stop):
# F is read in the units before the line's G20/G21, M70/M73 save and M72 restores before its G7/G8
STEPS = (Executor._feed_mode, Executor._feed, Executor._speed, Executor._tool, Executor._spindle,
         Executor._context, Executor._coolant, Executor._lengths_and_planes, Executor._offsets,
         Executor._path_mode, Executor._distance, Executor._motion, Executor._stop)
