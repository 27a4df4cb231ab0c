"""Facts of a hobbing program held to its own words and the records, read from its lines
(engine.simulation.hobbing.reading's steps) and the cuts the walk found:

* every hob speed S it commands within §C (engine.simulation.hobbing.cutting_speed) and equal to
  the header's n0;
* the tailstock, once the program clamps it (M20), clamped for every feed move: an M21 before
  or in a cut would let the work lift off the centre under the cutting force;
* the working area G25/G26 X… Y… Z… set once, before the first move (reference §A4);
* each `; CUT <name> X=<x> <word>` comment's word the direction of the cut that follows it
  (§B13), the header's cut count and feed mode the cuts' names and words.

Each function yields (step, message, refuses)."""
from __future__ import annotations

import re

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from .cutting_speed import speed_problem
from .header_facts import N0_LINE

CLAMP, RELEASE = 20, 21
FEED = 1
# `; CUT <name> X=<x> <word>`; an editor's words between the name and X= (a draft's TRIAL) are kept.
CUT_LINE = re.compile(r"; CUT (\S+)(?: .*)? X=\S+ (\S+)")
# The header's feed mode -> the word of the (rough, finish) cut; a single cut is the rough one
# (engine.hobbing.choices: the paper's single rough cut).
FEED_MODES = {"climb": ("CLIMB", "CLIMB"), "conventional": ("CONVENTIONAL", "CONVENTIONAL"),
              "conventional-climb": ("CONVENTIONAL", "CLIMB")}
CUT_NAMES = {1: ("SINGLE",), 2: ("ROUGH", "FINISH")}
UNIT_SEPARATOR = "/"   # a cluster gear's mode per unit, unit 1's/unit 2's (the header says it so)


def header_n0(steps) -> tuple | None:
    """(step, n0, cuts, feed mode) of the `; n0=…` line, or None."""
    for step in steps:
        match = N0_LINE.fullmatch(step.line)
        if match:
            return step, int(match.group(1)), int(match.group(3)), match.group(4)
    return None


def speed_facts(steps, gear: Gear, hob: Hob):
    """Every S the program commands: within §C, and the n0 of every `; n0=` line."""
    stated_lines = [(step, int(match.group(1))) for step in steps for match in [N0_LINE.fullmatch(step.line)] if match]
    for step in steps:
        speed = step.item.speed if step.kind == "block" and step.item.area is None else None
        if speed is None:
            continue
        problem = speed_problem(speed, gear, hob)
        if problem:
            yield step, problem[0] + " (reference §B4, §C)", problem[1]
        for stated, n0 in stated_lines:
            if speed != n0:
                yield step, (f"S{speed:g} commands the hob at {speed:g} r/min; the header states n0={n0} "
                             f"(line {stated.number})"), True


def tailstock_facts(steps):
    """Once the program clamps the tailstock, every G1 runs clamped; M21 counts as released
    already during its block's motion, M20 as clamped only after it (the unsafe way round)."""
    if not any(step.kind == "block" and CLAMP in step.m_codes for step in steps):
        return
    clamped, released_at = False, None
    for step in steps:
        if step.kind != "block":
            continue
        if RELEASE in step.m_codes:
            released_at = step.number
        cuts = step.item.moves and step.item.motion == FEED and step.item.area is None
        if cuts and (not clamped or RELEASE in step.m_codes):
            why = f"released by M21 at line {released_at}" if released_at else "not yet clamped (M20)"
            yield step, (f"the hob feeds with the tailstock {why}: the program clamps it, so every cut runs "
                         "clamped (the work would lift off the centre)"), True
        clamped = (clamped or CLAMP in step.m_codes) and RELEASE not in step.m_codes


def area_facts(steps):
    """G25/G26 X… Y… Z… once each, before the first move (reference §A4)."""
    set_before, moved = set(), False
    for step in steps:
        if step.kind != "block":
            continue
        block = step.item
        if block.area is not None and block.positions:
            word = "G25" if block.area == "lower" else "G26"
            if block.area in set_before or moved:
                yield step, (f"{word} {'again' if block.area in set_before else 'after the first move'}: the working "
                             "area is set once, before any motion (reference §A4)"), True
            set_before.add(block.area)
        elif block.moves:
            moved = True


def cut_directions(steps, machine: Machine, starts: frozenset = frozenset()):
    """(comment step, name, word, Z direction in the DIN frame (−1 down, +1 up, 0 none, BOTH), moves Y)
    for each `; CUT` comment: every feed move after it (to the next) that changes Z gives the
    direction; moves both ways are BOTH (adversary 29: a 1 µm move down before a pass fed up made
    the pass CLIMB). With `starts` (the walk's cuts' first lines), a stretch also begins at each
    of those lines, named and said None."""
    z_sense = -1 if int(machine.z_direction) < 0 else 1
    found: list[list] = []
    position: dict[str, float] = {}
    for step in steps:
        match = CUT_LINE.fullmatch(step.line)
        if match or step.number in starts:
            found.append([step, *(match.groups() if match else (None, None)), 0, False])
        if step.kind != "block" or not step.item.moves or step.item.area is not None:
            continue
        positions = step.item.positions
        if found and step.item.motion == FEED:
            _direction(found[-1], positions, position, z_sense)
        position.update(positions)
    return found


BOTH = 2   # a cut feeding both down and up along Z: neither climb nor conventional


def _direction(cut: list, positions: dict, position: dict, z_sense: int) -> None:
    if "Y" in positions and positions["Y"] != position.get("Y", positions["Y"]):
        cut[4] = True
    if "Z" in positions and "Z" in position and positions["Z"] != position["Z"]:
        sense = z_sense * (1 if positions["Z"] > position["Z"] else -1)
        cut[3] = sense if cut[3] in (0, sense) else BOTH


def cut_word_facts(steps, machine: Machine):
    """§B13 (Phillips): climb hobbing turns the hob against its feed at the contact. The hob
    turns in its cutting direction under M3, which the engine's DIN frame takes as the teeth
    moving up (+Z) where they meet the work: climb feeds down (−Z), conventional up; a worm
    wheel's RADIAL cut has no axial or tangential pass, its TANGENTIAL cut feeds along Y and not
    along Z (a Z pass said TANGENTIAL would escape the header's feed mode)."""
    for step, _, word, z, along_y in cut_directions(steps, machine):
        wanted = {"CLIMB": z == -1, "CONVENTIONAL": z == 1, "RADIAL": z == 0 and not along_y,
                  "TANGENTIAL": along_y and z == 0}.get(word)
        if wanted is None:
            yield step, f"the cut is said {word}: not CLIMB, CONVENTIONAL, RADIAL or TANGENTIAL", True
        elif not wanted:
            made = ("feeds both down and up along Z" if z == BOTH else "feeds down (−Z, DIN)" if z < 0 else
                    "feeds up (+Z, DIN)" if z > 0 else "feeds along Y" if along_y else "has no axial pass")
            yield step, f"the cut is said {word} but {made}: it is {_actual(z, along_y)} (reference §B13)", True


def _actual(z: int, along_y: bool) -> str:
    if z == BOTH:
        return "neither CLIMB nor CONVENTIONAL"
    return "CLIMB" if z < 0 else "CONVENTIONAL" if z > 0 else "TANGENTIAL" if along_y else "RADIAL"


def cut_count_facts(steps, machine: Machine, report, units: int):
    """The header's cuts are the cuts the walk follows, per unit, and the `; CUT` comments' names
    (SINGLE, or ROUGH then FINISH, per unit; a program without them states a feed mode nothing
    holds it to); its feed mode the comments' words, each cut's unit the one the walk found it cut."""
    stated = header_n0(steps)
    cuts = cut_directions(steps, machine)
    if stated is None:
        return
    step, _, count, mode = stated
    names = CUT_NAMES.get(count, ())
    if not cuts and names:   # no `; CUT` comments: the header's mode is held to the walk's passes
        cuts = walked_cuts(steps, machine, report, names)
    if len(report.cuts) != count * units:
        yield step, (f"the header states cuts={count}; the simulation follows {len(report.cuts)} cut(s) over "
                     f"{units} unit(s)"), True
    elif any(cut[0].kind == "comment" for cut in cuts) and [cut[1] for cut in cuts] != list(names) * units:
        yield step, (f"the header states cuts={count}; the program's `; CUT` comments name "
                     f"{' '.join(cut[1] for cut in cuts) or 'none'} over {units} unit(s)"), True
    axial = [cut for cut in cuts if cut[2] not in NOT_AXIAL]
    cut_units = _cut_units(cuts, report, count)
    if axial and not _feed_mode_kept(mode, cuts, cut_units, units):
        said = [(f"unit {unit} " if units > 1 else "") + f"{cut[1]} {cut[2]}"
                for cut, unit in zip(cuts, cut_units) if cut[2] not in NOT_AXIAL]
        yield step, f"the header states feed mode {mode}; the cuts are {', '.join(said)}", True
    worm = [cut for cut in cuts if cut[2] in NOT_AXIAL]
    if worm and (axial or any(cut[2] != mode.upper() for cut in worm)):
        cut_words = " ".join(f"{cut[1]} {cut[2]}" for cut in cuts)
        yield step, (f"the header states feed {mode}; the cuts are {cut_words} (a worm wheel's header names its "
                     "worm feed, radial or tangential)"), True


NOT_AXIAL = ("RADIAL", "TANGENTIAL")   # a worm wheel's cuts: no axial pass, no feed mode


def walked_cuts(steps, machine: Machine, report, names: tuple) -> list[list]:
    """The walk's cuts as `; CUT` comments would say them: named by their place in their unit's
    coupling (a unit is roughed and finished in one), said by their direction (BOTH: both ways)."""
    passes = cut_directions(steps, machine, frozenset(done.number for done in report.cuts))
    for index, cut in enumerate(passes):
        cut[1] = names[index % len(names)]
        cut[2] = "CLIMB+CONVENTIONAL" if cut[3] == BOTH else _actual(cut[3], cut[4])
    return passes


def _cut_units(cuts: list, report, count: int) -> list[int]:
    """The unit number each `; CUT` comment's cut entered: the walk's first cut starting after the
    comment (its unit "unit <n> (...)"), else by place (count comments per unit, unit 1's first)."""
    found = []
    for index, cut in enumerate(cuts):
        entered = next((done.unit for done in report.cuts if done.number >= cut[0].number), "")
        words = entered.split()
        found.append(int(words[1]) if len(words) > 1 and words[1].isdecimal() else 1 + index // max(count, 1))
    return found


def _feed_mode_kept(mode: str, cuts: list, cut_units: list[int], units: int) -> bool:
    """Every axial cut's word is the one the header's mode gives its unit and its place (rough or
    finish): one mode for all units, or one per unit ("climb/conventional": unit 1's/unit 2's)."""
    modes = mode.split(UNIT_SEPARATOR)
    if len(modes) not in (1, units) or any(one not in FEED_MODES for one in modes):
        return False
    for cut, unit in zip(cuts, cut_units):
        words = FEED_MODES[modes[min(unit - 1, len(modes) - 1)]]
        if cut[2] not in NOT_AXIAL and cut[2] != words[0 if cut[1] != "FINISH" else 1]:
            return False
    return True
