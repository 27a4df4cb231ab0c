"""What the machine must be doing before it moves, per dialect, as data, and the state the walk
keeps to know it.

A position is right only in the state it is read in: a move in unstated units or positioning
is read in whatever the last program left; a cut with the hob spindle stopped, or with the
table not coupled to it, breaks the hob; a cut with no tool offset active moves the turret,
not the tool tip, to the position (reference §E: T0100 cancels the offset); a feed in an
unstated mode is whatever the last program left. So every event of a line (a G or
M code, a keyword, a statement, an S, T or D word) sets or clears facts, and every motion and
statement needs facts to hold (or not to hold) before it. M30 ends the program: nothing after
it is read by the control, so nothing may follow (but the ISO closing %).

A hobbing program (design notes §7, reference §A7) moves the hob only in the work offset its
machine record names (G54…G57), couples the table only with Y (the shift axis) positioned, so
the generating zone lies where the program says, and ends with the coupling switched off and
deleted (EGOFS(C), EGDEL(C)): the next program's EGDEF alarms while a definition exists."""
from __future__ import annotations

import msgspec

from .refusals import Refused

SPINDLE_SPEED, SPINDLE_TURNING, TOOL_OFFSET = "spindle speed", "spindle turning", "tool offset"
COUPLING_DEFINED, COUPLED, ENDED = "coupling defined", "coupled", "ended"
TOOL_CHANGE, OFFSET_ON, OFFSET_OFF = "tool change", "offset on", "offset off"
WORK_OFFSET, Y_POSITIONED = "work offset", "Y positioned"
SPEED_BOUNDED, FEED_TYPE = "spindle speed bounded", "feed type stated"
Y_POSITION = "Y position"     # the event of a block (or the shift clamp) that positions Y
SWIVEL = "A position"         # the event of a block that swivels the hob head (A)


class Effect(msgspec.Struct, frozen=True):
    """What one event does: facts it sets and facts it clears (a block's clears come first)."""
    sets: frozenset[str] = frozenset()
    clears: frozenset[str] = frozenset()


def sets(*facts: str) -> Effect:
    return Effect(sets=frozenset(facts))


def clears(*facts: str) -> Effect:
    return Effect(clears=frozenset(facts))


class Need(msgspec.Struct, frozen=True):
    """A fact that must hold before a motion or statement (or, not `present`, must not)."""
    fact: str
    reason: str
    present: bool = True


class Needs:
    """The needs of one motion or statement, in the order they are said, and as sets to test."""

    def __init__(self, *needs: Need) -> None:
        self.needs = needs
        self.required = frozenset(need.fact for need in needs if need.present)
        self.forbidden = frozenset(need.fact for need in needs if not need.present)

    def __add__(self, other: Needs) -> Needs:
        return Needs(*self.needs, *other.needs)

    def check(self, facts: set[str], could_hold: set[str] | None = None) -> None:
        """`facts` hold for sure; `could_hold` (default: the same) may hold by the time the motion or
        event runs, the block's own M codes output before it (the builder's choice)."""
        could_hold = facts if could_hold is None else could_hold
        if self.required <= facts and not self.forbidden & could_hold:
            return
        raise Refused(next(need.reason for need in self.needs
                           if (need.fact not in facts if need.present else need.fact in could_hold)))


class StateRules(msgspec.Struct, frozen=True):
    """A dialect's machine-state rules: what each event sets or clears, and what each motion or statement needs."""
    effects: dict[str, Effect]   # event -> Effect
    needs: dict[str, Needs]      # "G1" (a block moving with G1), "EGDEF" … -> Needs


def stated(*codes: int) -> dict[str, Effect]:
    """Modal G codes that, once a block gives them, hold for the rest of the program."""
    return {f"G{code}": sets(f"G{code}") for code in codes}


def needs_stated(*codes: int) -> Needs:
    return Needs(*(Need(f"G{code}", f"motion before G{code} ({STATED_CODES[code]}) is stated: the control would "
                                    "keep whatever the last program left") for code in codes))


STATED_CODES = {71: "mm", 21: "mm", 90: "absolute positions", 94: "feed in mm/min", 98: "feed in mm/min",
                18: "the ZX plane of the arcs", 40: "no tool-nose radius compensation",
                97: "spindle speed in r/min"}

SPINDLE = {"S": sets(SPINDLE_SPEED), "M3": sets(SPINDLE_TURNING), "M5": clears(SPINDLE_TURNING)}
END = {"M30": sets(ENDED)}
SPINDLE_NEEDS = Needs(
    Need(SPINDLE_SPEED, "a cut before any spindle speed S: the spindle would turn at whatever S the control holds"),
    Need(SPINDLE_TURNING, "a cut with the spindle stopped: M3 with S above 0 first, and no M5 since "
                                   "(nor in the cut's own block)"))
# 840D: a tool change T activates the edge the machine data chooses, so only a D in the same
# block or after it says the offset; D0 deselects it. ISO T<tool><offset>: offset 00 cancels.
OFFSETS = {TOOL_CHANGE: clears(TOOL_OFFSET), OFFSET_ON: sets(TOOL_OFFSET), OFFSET_OFF: clears(TOOL_OFFSET)}
OFFSET_NEEDS = Needs(Need(TOOL_OFFSET, "a cut with no tool offset active (T…D0, T0100, or a T without its D): "
                                       "the position would be the turret's, not the tool tip's"))

AREA_REASON = "motion before G25/G26 and WALIMON set the working area"
AREA_NEEDS = Needs(*(Need(fact, AREA_REASON) for fact in ("G25", "G26", "WALIMON")))
COUPLING = {"EGDEF": sets(COUPLING_DEFINED), "EGON": sets(COUPLED),
            "EGOFS": clears(COUPLED), "EGDEL": clears(COUPLED, COUPLING_DEFINED)}
WORK_OFFSETS = {f"G{code}": sets(WORK_OFFSET) for code in (54, 55, 56, 57)}
WORK_OFFSET_NEEDS = Needs(
    Need(WORK_OFFSET, "a hob move before a work offset (G54…G57) is selected: the position would be read in "
                      "whatever frame the last program left"))
HOB_MOVE_NEEDS = AREA_NEEDS + needs_stated(90, 71) + WORK_OFFSET_NEEDS
HOB_CUT_NEEDS = HOB_MOVE_NEEDS + needs_stated(94) + SPINDLE_NEEDS + Needs(
    Need(COUPLED, "a cut with the table not coupled to the hob: EGON(C,…) first, and no EGOFS(C) since"))

HOBBING_STATE = StateRules(
    effects={**stated(25, 26, 71, 90, 94), "WALIMON": sets("WALIMON"), **SPINDLE, **END, **COUPLING,
             **WORK_OFFSETS, **OFFSETS, Y_POSITION: sets(Y_POSITIONED)},
    needs={"G0": HOB_MOVE_NEEDS, "G1": HOB_CUT_NEEDS,
           "EGDEF": Needs(Need(COUPLING_DEFINED, "EGDEF(C…) while C's coupling is defined: EGDEL(C) first (reference "
                                                 "§A7: a second definition alarms)", present=False)),
           "EGON": Needs(Need(COUPLING_DEFINED, "EGON before EGDEF defined the coupling"),
                         Need(Y_POSITIONED, "EGON before Y (the hob shift) is positioned: the generating zone "
                                            "would lie wherever the last program left the hob (reference §A7)")),
           "EGOFS": Needs(),
           "EGDEL": Needs(Need(COUPLED, "EGDEL(C) while the coupling is on: EGOFS(C) first", present=False)),
           "M30": Needs(Need(COUPLING_DEFINED, "M30 with C's coupling still defined: EGOFS(C) then EGDEL(C) first "
                                               "(the next program's EGDEF would alarm, reference §A7)",
                             present=False))},
)


def fanuc_hobbing_state(on: str, off: str, form: str) -> StateRules:
    """Fanuc hobbing (issue 30): the electronic gear box's `on` command (G81 T… L…, written `form`)
    synchronises the table to the hob spindle, a second one changes the ratio, `off` (G80) cancels
    it. Every move in mm, absolute, in a work offset; a cut (G1) also at a feed per minute with
    the hob turning and the table synchronised; `on` only with Y (the hob shift) positioned, as
    EGON (reference §A7); M30 only after `off`, so the next program does not start synchronised;
    no Y, A or T while synchronised (fanuc_synchronised_needs).
    No working area: Fanuc's G25/G26 switch spindle-speed fluctuation detection."""
    move = needs_stated(90, 21) + WORK_OFFSET_NEEDS
    cut = move + needs_stated(94) + SPINDLE_NEEDS + Needs(
        Need(COUPLED, f"a cut with the table not synchronised to the hob: {form} first, and no {off} since"))
    return StateRules(
        effects={**stated(21, 90, 94), **SPINDLE, **END, **WORK_OFFSETS, on: sets(COUPLED), off: clears(COUPLED),
                 Y_POSITION: sets(Y_POSITIONED), TOOL_CHANGE: Effect()},
        needs={"G0": move, "G1": cut, **fanuc_synchronised_needs(on, off),
               on: Needs(Need(Y_POSITIONED, f"{on} before Y (the hob shift) is positioned: the generating zone "
                                            "would lie wherever the last program left the hob (reference §A7)")),
               off: Needs(),
               "M30": Needs(Need(COUPLED, f"M30 while the table is synchronised to the hob: {off} first (the "
                                          "next program would start synchronised)", present=False))})


def fanuc_synchronised_needs(on: str, off: str) -> dict[str, Needs]:
    """What must wait for `off` (G80) on a Fanuc hobber (fanuc-egb.md §F6): G81 has no Y term, so
    a Y move (hob shift) while synchronised slides the hob's thread against the teeth it cuts,
    uncompensated; a swivel A turns the hob's thread against them; a tool call T changes the hob
    the table follows (and with the hob turning, at the cut). Each is refused while synchronised,
    any Y or A word, G0 or G1, at the position held or not."""
    while_on = f"the table is synchronised to the hob ({on}, no {off} since)"
    return {Y_POSITION: Needs(Need(COUPLED, f"a Y move (hob shift) while {while_on}: {on} has no Y term, so "
                                            "the hob's thread would slide against the teeth it cuts (fanuc-egb.md "
                                            f"§F6); shift before {on} or after {off}", present=False)),
            SWIVEL: Needs(Need(COUPLED, f"an A move (swivel) while {while_on}: the hob's thread would turn "
                                        f"against the teeth it cuts; swivel before {on}", present=False)),
            TOOL_CHANGE: Needs(Need(COUPLED, f"a tool call T while {while_on}: the table would follow "
                                             f"another hob; {off} and M5 first", present=False),
                               Need(SPINDLE_TURNING, "a tool call T with the hob turning (M3 before or in its block, "
                                                     "no M5 since): "
                                                     "a hob change at the cut; M5 first", present=False))}


FANUC_HOBBING_STATE = fanuc_hobbing_state("G81", "G80", "G81 T… L…")
FANUC_G81_4_HOBBING_STATE = fanuc_hobbing_state("G81.4", "G80.4", "G81.4 R… L…")

LATHE_840D_MOVE = Needs(Need("DIAMON", "motion before DIAMON: X would be a radius, and the travel is checked as a "
                                      "diameter")) + needs_stated(71, 90)
LATHE_840D_THREAD = LATHE_840D_MOVE + needs_stated(18, 40, 97) + SPINDLE_NEEDS + OFFSET_NEEDS
# A cut turns at r/min (G97 S…) or at a constant cutting speed G96 whose r/min rise as the
# diameter falls, up to the clamp LIMS (reference sinumerik-lathe §S6): G96 without LIMS is unbounded at the axis.
# The feed is per minute (G94) or per turn (G95); either, once stated.
LATHE_840D_CUT = LATHE_840D_MOVE + needs_stated(18, 40) + Needs(
    Need(SPEED_BOUNDED, "a cut before the spindle speed is bounded: G97 S… in r/min, or G96 with its clamp "
                        "LIMS=… (without it the speed rises without limit toward the axis)")
) + SPINDLE_NEEDS + OFFSET_NEEDS + Needs(
    Need(FEED_TYPE, "motion before G94 or G95 (feed per minute or per turn) is stated: the control would keep "
                    "whatever the last program left"))
LATHE_840D_SPEEDS = {"G97": sets("G97", SPEED_BOUNDED), "G96": Effect(clears=frozenset({"G97", SPEED_BOUNDED})),
                     "LIMS": sets(SPEED_BOUNDED), "G94": sets("G94", FEED_TYPE), "G95": sets(FEED_TYPE),
                     "M4": sets(SPINDLE_TURNING)}
LATHE_840D_STATE = StateRules(
    effects={**stated(18, 40, 71, 90), "DIAMON": sets("DIAMON"), **SPINDLE, **END, **OFFSETS, **LATHE_840D_SPEEDS},
    needs={"G0": LATHE_840D_MOVE, "G1": LATHE_840D_CUT, "G2": LATHE_840D_CUT, "G3": LATHE_840D_CUT,
           "G33": LATHE_840D_THREAD},
)

LATHE_ISO_MOVE = needs_stated(21, 90)
LATHE_ISO_THREAD = LATHE_ISO_MOVE + needs_stated(18, 40, 97) + SPINDLE_NEEDS + OFFSET_NEEDS
LATHE_ISO_CUT = LATHE_ISO_THREAD + needs_stated(98)
LATHE_ISO_STATE = StateRules(
    effects={**stated(18, 21, 40, 90, 97, 98), **SPINDLE, **END, **OFFSETS,
             "M4": sets(SPINDLE_TURNING), "M2": sets(ENDED)},
    needs={"G0": LATHE_ISO_MOVE, "G1": LATHE_ISO_CUT, "G2": LATHE_ISO_CUT, "G3": LATHE_ISO_CUT,
           "G32": LATHE_ISO_THREAD},
)

# LinuxCNC (docs/reference/linuxcnc-lathe.md §3): the expander writes every block in mm (G21 once
# the program states its units), absolute, X a diameter, each feed block with its G94/G95; a tool
# change M6 activates no offset until G43 applies the tool table's (G49 cancels it).
LINUXCNC_OFFSET_NEEDS = Needs(Need(TOOL_OFFSET, "a cut with no tool length offset active (G43 after the tool "
                                                "change M6, no G49 since): the position would be the spindle "
                                                "nose's, not the tool tip's"))
LINUXCNC_MOVE = needs_stated(21)
LINUXCNC_CUT = LINUXCNC_MOVE + needs_stated(18) + SPINDLE_NEEDS + LINUXCNC_OFFSET_NEEDS
LINUXCNC_STATE = StateRules(
    effects={**stated(18, 21, 40), **SPINDLE, "M4": sets(SPINDLE_TURNING), **END, "M2": sets(ENDED), **OFFSETS,
             "G43": sets(TOOL_OFFSET), "G49": clears(TOOL_OFFSET), "M6": Effect()},
    needs={"G0": LINUXCNC_MOVE, "G1": LINUXCNC_CUT, "G2": LINUXCNC_CUT, "G3": LINUXCNC_CUT, "G33": LINUXCNC_CUT,
           "M6": Needs(Need(SPINDLE_TURNING, "a tool change with the spindle turning (M3/M4 and no M5 since): "
                                             "a tool change at the cut; stop the spindle (M5) and retract first",
                            present=False))},
)


class State:
    """The facts that hold after the lines so far."""

    def __init__(self, rules: StateRules) -> None:
        self.rules = rules
        self.facts: set[str] = set()

    def apply(self, events: frozenset[str]) -> None:
        effects = [self.rules.effects[event] for event in events if event in self.rules.effects]
        for effect in effects:
            self.facts -= effect.clears
        for effect in effects:
            self.facts |= effect.sets

    def check(self, what: str, pending: frozenset[str] = frozenset()) -> None:
        """Refused unless what `what` (a motion "G1", a statement "EGDEF") needs holds; a motion no
        rule speaks of is refused too. `pending`: the events of the same block (M5, T…), which the
        control may output before the motion: a fact they clear is not counted on (`G1 Z… M5`
        would cut with the hob stopping), a fact they set is feared (`T1 M3`)."""
        needs = self.rules.needs.get(what)
        if needs is None:
            raise Refused(f"no rule of this dialect says what {what} needs; it is not verified")
        needs.check(*self._with(pending))

    def check_event(self, event: str, pending: frozenset[str] = frozenset()) -> None:
        """Refused unless what an event (M30) needs holds, where the dialect has a rule for it;
        `pending` as in check, the block's other events."""
        needs = self.rules.needs.get(event)
        if needs is not None:
            needs.check(*self._with(pending))

    def _with(self, pending: frozenset[str]) -> tuple[set[str], set[str]]:
        """(the facts that hold for sure, the facts that could hold) with `pending` output or not."""
        effects = [self.rules.effects[event] for event in pending if event in self.rules.effects]
        cleared = set().union(*(effect.clears for effect in effects))
        added = set().union(*(effect.sets for effect in effects))
        return self.facts - cleared, self.facts | added

    @property
    def ended(self) -> bool:
        return ENDED in self.facts
