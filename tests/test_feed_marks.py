"""Feed marks held to the quality grade (reference §B6, issue 29): the engine bounds the last
cut's axial feed so its marks δ = f_a²·sin α_n/(4·d_a0) stay within the share of the helix form
tolerance the gear's grade allows, and the simulation refuses a program whose last cut is
deeper. Every expected number comes from the reference's formulas (tests/helpers/feed_mark_reference.py),
the programs' feeds from their own F words and header."""
from __future__ import annotations

import math
import random
import re

import pytest
from helpers import feed_mark_reference as reference
from helpers.random_gears import MODULES, insert_gears

from engine.errors import EngineError
from engine.gears.cutting_data import CuttingData
from engine.gears.feed_marks import allowed_depth, bounded_for_marks, mark_depth
from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear, instantiate_gears
from engine.programs.options import RunMode
from engine.simulation import simulate_program

MACHINE = "hobber-840d"
N0_LINE = re.compile(r"; n0=([0-9]+) r/min table=\S+ r/min")
HOB_LINE = re.compile(r"; HOB (\S+) z0=([0-9]+) da0=(\S+)")
UNIT_LINE = re.compile(r"; UNIT [0-9]+ z=([0-9]+) ")
FEED = re.compile(r"\bF([0-9.]+)")


def graded(conn, grade: int, *gear_ids: int) -> None:
    conn.execute("UPDATE gear SET quality_grade = %s WHERE id = ANY(%s)", (grade, list(gear_ids)))


def last_cut_feeds(lines: list[str], teeth: int) -> list[float]:
    """f [mm per workpiece revolution] of every axial pass move of the last cuts (SINGLE, FINISH),
    from the modal F word and the table speed n0·z0/z2 of the unit being cut (§B5)."""
    n0 = next(int(m.group(1)) for line in lines for m in [N0_LINE.match(line)] if m)
    starts = next(int(m.group(2)) for line in lines for m in [HOB_LINE.match(line)] if m)
    feeds, feed, last, unit_teeth = [], 0.0, False, teeth
    for line in lines:
        unit = UNIT_LINE.match(line)
        unit_teeth = int(unit.group(1)) if unit else unit_teeth
        if line.startswith("; CUT "):
            last = line.split()[2] in ("SINGLE", "FINISH")
        word = FEED.search(line) if line.startswith(("G1", "G0")) else None
        feed = float(word.group(1)) if word else feed
        if last and line.startswith("G1") and " Z" in f" {line}":
            feeds.append(feed / (n0 * starts / unit_teeth))
    return feeds


def gear_limit(gear) -> float:
    """The smallest allowed depth over the gear's toothings (unit 1 and a duplex's others)."""
    toothings = [(gear.teeth, gear.face_width)] + [(unit.teeth, unit.face_width) for unit in gear.units]
    return min(reference.limit(gear.quality_grade, gear.module, teeth, gear.helix_angle, width)
               for teeth, width in toothings)


def test_the_depths_and_limits_are_the_references():
    """δ at the §C roughing maximum for m2 (3.0 mm/rev) with d_a0 70: 9·sin 20°/280 mm ≈ 11 µm, the
    8–12 µm of the issue; grade 6 on m2 z30 b20 allows half of (0.07·√60 + 0.45·√20 + 4)·√2 µm."""
    assert mark_depth(3.0, 20, 70) == pytest.approx(9 * math.sin(math.radians(20)) / 280)
    assert mark_depth(3.0, 20, 70) == pytest.approx(0.011, abs=0.0005)
    expected = 0.5 * (0.07 * math.sqrt(60) + 0.45 * math.sqrt(20) + 4) * math.sqrt(2) / 1000
    assert allowed_depth(6, 60, 20) == pytest.approx(expected)
    assert allowed_depth(7, 60, 20) == pytest.approx(expected * math.sqrt(2))   # one class coarser: ×√2
    assert allowed_depth(None, 60, 20) == pytest.approx(expected * 2 ** 1.0)    # no grade: 8, as the hob match


def test_a_grade_6_m2_gear_is_cut_with_its_marks_within_the_limit(conn):
    """Gear 42 (m2 z19 b20 spur, d_a0 70) graded 6: its single cut runs at the bounded feed, the
    F word written at or below it, and the note says so."""
    graded(conn, 6, 42)
    program = instantiate_gear(conn, 42)
    gear = load_gear(conn, 42)
    (feed,) = last_cut_feeds(program.lines, gear.teeth)
    limit = reference.limit(6, 2, 19, 0, 20)
    assert reference.depth(feed, 20, 70) <= limit
    bound = reference.bound(6, 2, 19, 0, 20, 20, 70)
    assert feed == pytest.approx(bound, abs=0.1 / (246 / 19))        # the F word floored to 0.1 mm/min
    assert any("bounded to" in note and "feed marks" in note for note in program.notes)


def test_two_cuts_bound_the_finish_only(conn):
    """With two cuts the rough pass keeps the case's feed; the finish pass is within the limit."""
    graded(conn, 6, 42)
    program = instantiate_gear(conn, 42, choices=Choices(cuts=2))
    for feed in last_cut_feeds(program.lines, 19):
        assert reference.depth(feed, 20, 70) <= reference.limit(6, 2, 19, 0, 20)


def edited(lines: list[str], new_feed: float) -> list[str]:
    """The program with the F word of its last cut's pass raised to `new_feed` mm/min."""
    out, last = list(lines), False
    for at, line in enumerate(out):
        if line.startswith("; CUT "):
            last = line.split()[2] in ("SINGLE", "FINISH")
        elif last and line.startswith("G1") and " Z" in f" {line}" and FEED.search(line):
            out[at] = FEED.sub(f"F{new_feed:.1f}", line)
    return out


@pytest.mark.parametrize("cuts", [1, 2])
def test_a_program_hand_edited_to_a_larger_last_feed_is_refused(conn, cuts):
    """Raised to 1.2× the bound (still below the §C maxima), the last cut's marks are 1.44× the
    limit: refused on that line, naming the feed marks; the program as made is not."""
    graded(conn, 6, 42)
    program = instantiate_gear(conn, 42, choices=Choices(cuts=cuts))
    gear, machine = load_gear(conn, 42), load_machine(conn, MACHINE)
    hob = {hob.id: hob for hob in load_hobs(conn)}["H-M2-AA-R1"]
    assert not [f for f in simulate_program(program.lines, gear, hob, machine, "TEST").refusals
                if "feed marks" in f.message]
    table = 246 * 1 / 19
    raised = 1.2 * reference.bound(6, 2, 19, 0, 20, 20, 70) * table
    lines = edited(program.lines, raised)
    report = simulate_program(lines, gear, hob, machine, "TEST")
    marks = [f for f in report.refusals if "feed marks" in f.message]
    assert marks and "grade 6" in marks[0].message
    assert f"F{raised:.1f}" in marks[0].line                             # on the pass that cuts them


def test_an_allowance_for_grinding_is_not_held_to_the_marks(conn):
    """A job leaving stock for shaving or grinding: the stock takes the marks, the feed is not bounded."""
    graded(conn, 6, 42)
    bounded = instantiate_gear(conn, 42)
    ground = instantiate_gear(conn, 42, choices=Choices(allowance=0.1))
    assert last_cut_feeds(ground.lines, 19)[0] > last_cut_feeds(bounded.lines, 19)[0]


def test_a_given_feed_above_the_bound_is_refused_not_changed(conn):
    gear = load_gear(conn, 42)
    hob = {hob.id: hob for hob in load_hobs(conn)}["H-M2-AA-R1"]
    cutting = CuttingData(50.0, 246, 3.0, 1.2, 1.0, "given")
    with pytest.raises(EngineError, match="feed marks"):
        bounded_for_marks(cutting, gear, hob, 1, 0.0, frozenset({"axial_feed_rough"}))
    assert bounded_for_marks(cutting, gear, hob, 1, 0.0).axial_feed_rough < 3.0


def test_every_program_of_a_grade_6_batch_is_within_its_limit(conn):
    """Every seeded gear graded 6, made in one batch: each last cut's marks within its grade's limit."""
    ids = [row[0] for row in conn.execute("SELECT id FROM gear ORDER BY id")]
    graded(conn, 6, *ids)
    batch = instantiate_gears(conn, min(ids), max(ids), mode=RunMode(skip_bad=True))
    # the library has no hob of class AA or finer for some (grade 6 needs AA, engine.gears.hob_matching)
    assert all("class" in reason and "feed marks" not in reason for reason in batch.skipped), batch.skipped
    assert batch.programs + len(batch.skipped) == len(ids) and batch.programs >= 5
    rows = conn.execute("SELECT lines FROM program WHERE id BETWEEN %s AND %s",
                        (batch.first_program_id, batch.last_program_id)).fetchall()
    hobs = {hob.id: hob for hob in load_hobs(conn)}
    checked = 0
    for (lines,) in rows:
        gear = load_gear(conn, int(next(line.split()[2] for line in lines if line.startswith("; GEAR "))))
        hob = hobs[next(m.group(1) for line in lines for m in [HOB_LINE.match(line)] if m)]
        for feed in last_cut_feeds(lines, gear.teeth):
            assert reference.depth(feed, gear.pressure_angle, hob.tip_diameter) <= gear_limit(gear) * (1 + 1e-9)
            checked += 1
    assert checked >= batch.programs - 1    # every gear but a worm wheel has an axial pass


# Hobs sized roughly as DIN 8002 gives them (module -> tip diameter, mm), 1-start AAA (fine enough for
# grade 6), both hands: a random grade-6 population is cut with them.
POPULATION_HOBS = dict(zip(MODULES, (50, 63, 70, 75, 80, 90)))


@pytest.mark.slow   # a random population made and read: 1.4 s
def test_a_random_grade_6_population_keeps_every_last_cut_within_its_limit(conn):
    """60 spur and helical gears, m1–4 (the seeded machine's range), 12–120 teeth, b 6–12·m, grade
    6: before issue 29 about two in three single cuts left deeper marks than the grade allows (the
    review: 357 of 410). Every program made now keeps them within; a gear refused is refused for
    another reason (a small root meeting the work-holding), never for its feed marks."""
    rng = random.Random(29)
    for module, tip in POPULATION_HOBS.items():
        for hand in "RL":
            conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, coating) "
                         "VALUES (%s, %s, 1, %s, %s, %s, 'AAA', 'TiN')",
                         (f"P-M{module}-{hand}", module, tip, 30 * module + 60, hand))
    ids = insert_gears(conn, rng, 80000, 60, grade=6)
    batch = instantiate_gears(conn, ids[0], ids[-1], mode=RunMode(skip_bad=True))
    assert batch.programs >= 0.9 * len(ids) and not [r for r in batch.skipped if "feed marks" in r]
    hobs = {hob.id: hob for hob in load_hobs(conn)}
    rows = conn.execute("SELECT lines FROM program WHERE id BETWEEN %s AND %s",
                        (batch.first_program_id, batch.last_program_id)).fetchall()
    for (lines,) in rows:
        gear = load_gear(conn, int(next(line.split()[2] for line in lines if line.startswith("; GEAR "))))
        hob = hobs[next(m.group(1) for line in lines for m in [HOB_LINE.match(line)] if m)]
        feeds = last_cut_feeds(lines, gear.teeth)
        assert feeds, lines
        for feed in feeds:
            assert reference.depth(feed, 20, hob.tip_diameter) <= gear_limit(gear) * (1 + 1e-9)
