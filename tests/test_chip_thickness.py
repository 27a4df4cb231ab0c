"""Chip thickness as a constraint on the feed (reference §C1, issue 29): hob records carry their gashes
and profile, and every cylindrical gear's axial feed keeps Hoffmeister's h_max within 0.20 mm, for
1-, 2- and 3-start hobs alike (it replaces the ÷√z0 rule). Every expected number comes from the
reference's formula (tests/helpers/chip_reference.py), the programs' feeds from their own F words and
header lines."""
from __future__ import annotations

import json
import math
import random
import re

import pytest
from helpers import chip_reference as reference
from helpers.random_gears import insert_gears

from engine.gears.chip_thickness import ChipCase, feed_for_chip_thickness, max_chip_thickness
from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear, instantiate_gears
from engine.programs.options import RunMode
from engine.simulation import simulate_program

MACHINE = "hobber-840d"
N0_LINE = re.compile(r"; n0=([0-9]+) r/min table=\S+ r/min")
HOB_LINE = re.compile(r"; HOB (\S+) z0=([0-9]+) da0=(\S+)")
FEED = re.compile(r"\bF([0-9.]+)")
# §C table, roughing maxima f_a [mm per workpiece revolution] by module (interpolated between rows).
TABLE_ROUGH = ((1.0, 2.0), (2.0, 3.0), (3.0, 3.5), (4.0, 4.0))


def table_rough(module: float) -> float:
    if module <= TABLE_ROUGH[0][0]:
        return TABLE_ROUGH[0][1]
    for (m0, f0), (m1, f1) in zip(TABLE_ROUGH, TABLE_ROUGH[1:]):
        if module <= m1:
            return f0 + (f1 - f0) * (module - m0) / (m1 - m0)
    return TABLE_ROUGH[-1][1]


def pass_feeds(lines: list[str], teeth: int) -> list[tuple[float, float]]:
    """(f_a [mm per workpiece revolution], F [mm/min]) of every axial pass move (G1 with Z, any cut),
    from the modal F word and the table speed n0·z0/z2 (§B5)."""
    n0 = next(int(m.group(1)) for line in lines for m in [N0_LINE.match(line)] if m)
    starts = next(int(m.group(2)) for line in lines for m in [HOB_LINE.match(line)] if m)
    table = n0 * starts / teeth
    found, feed = [], 0.0
    for line in lines:
        word = FEED.search(line) if line.startswith(("G1", "G0")) else None
        feed = float(word.group(1)) if word else feed
        if line.startswith("G1") and " Z" in f" {line}":
            found.append((feed / table, table))
    return found


def test_the_formula_is_the_references():
    """Hand-worked: m2 z30 spur, x 0, d_a0 70, 12 gashes, 1 start, f_a 3.0, T 4.5 mm:
    4.9·2·30^−0.542·17.5^−0.225·12^−0.877·1.5^0.511·2.25^0.319 ≈ 0.147 mm; a 2-start hob halves i,
    ×2^0.877 ≈ 1.84. The engine's h_max and its feed at 0.20 mm are the reference's."""
    assert reference.h_max(2, 30, 0, 0, 70, 12, 1, 3.0) == pytest.approx(0.1467, abs=0.0005)
    assert reference.h_max(2, 30, 0, 0, 70, 12, 2, 3.0) == pytest.approx(0.1467 * 2 ** 0.877, abs=0.001)
    for module, teeth, beta, x, tip, gashes, starts, feed in [
            (2, 30, 0, 0, 70, 12, 1, 3.0), (3, 41, 15, 0.2, 80, 14, 2, 2.0), (1.5, 48, 20, -0.3, 63, 9, 3, 1.1),
            (4, 25, 30, 0.5, 90, 16, 1, 4.0)]:
        case = ChipCase(module, teeth, beta, x, tip / 2, gashes, starts, 2.25 * module)
        assert max_chip_thickness(case, feed) == pytest.approx(
            reference.h_max(module, teeth, beta, x, tip, gashes, starts, feed), rel=1e-12)
        assert feed_for_chip_thickness(case) == pytest.approx(
            reference.feed_at_bound(module, teeth, beta, x, tip, gashes, starts), rel=1e-9)


def test_a_feed_above_the_bound_is_lowered_and_said(conn):
    """Gear 45 (m4 z25 spur, hob H-M4-A-R1 d_a0 90, 12 gashes): the history's rough feed, 3.5 mm/rev,
    makes chips of 0.27 mm; the program's rough pass runs at the bound instead, and the note says why."""
    assert reference.h_max(4, 25, 0, 0, 90, 12, 1, 3.5) > reference.ALLOWED
    program = instantiate_gear(conn, 45, choices=Choices(cuts=2))
    feeds = pass_feeds(program.lines, 25)
    bound = reference.feed_at_bound(4, 25, 0, 0, 90, 12, 1)
    assert max(feed for feed, _ in feeds) <= bound + 1e-9
    assert max(feed for feed, _ in feeds) > bound - 0.1 / min(table for _, table in feeds)   # at it, F to 0.1
    assert [note for note in program.notes if "Hoffmeister" in note and "bounded to" in note]


def population(conn, starts: int, rng: random.Random) -> list[int]:
    """30 spur and helical gears, m1–4, 12–120 teeth, grade 5, cut with AAA hobs of `starts` starts and
    9–16 gashes, both hands (the only hobs fine enough for grade 5: the seeded library's are AA and A)."""
    for module, tip in {1: 50, 1.5: 63, 2: 70, 2.5: 75, 3: 80, 4: 90}.items():
        for hand in "RL":
            conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, coating, "
                         "gashes) VALUES (%s, %s, %s, %s, %s, %s, 'AAA', 'TiN', %s)",
                         (f"C-M{module}-{hand}{starts}", module, starts, tip, 30 * module + 60, hand,
                          rng.randint(9, 16)))
    return insert_gears(conn, rng, 81000, 30, grade=5)


@pytest.mark.parametrize("starts", [1, 2, 3])
def test_every_program_of_a_population_keeps_its_chips_within_the_bound(conn, starts):
    """Every axial pass of every program (rough and finish; an allowance for grinding, so the feed-mark
    bound of the last cut does not hide this one) makes chips of at most 0.20 mm by the reference's
    formula, and never feeds above the §C table. For multi-start hobs the bound binds on some passes:
    they run at it (to the F word's 0.1 mm/min), below the table's maximum."""
    ids = population(conn, starts, random.Random(290 + starts))
    batch = instantiate_gears(conn, ids[0], ids[-1], choices=Choices(allowance=0.1), mode=RunMode(skip_bad=True))
    assert batch.programs >= 0.9 * len(ids) and not [r for r in batch.skipped if "chip" in r or "feed" in r]
    hobs = {hob.id: hob for hob in load_hobs(conn)}
    rows = conn.execute("SELECT lines FROM program WHERE id BETWEEN %s AND %s",
                        (batch.first_program_id, batch.last_program_id)).fetchall()
    at_bound = 0
    for (lines,) in rows:
        gear = load_gear(conn, int(next(line.split()[2] for line in lines if line.startswith("; GEAR "))))
        hob = hobs[next(m.group(1) for line in lines for m in [HOB_LINE.match(line)] if m)]
        assert hob.starts == starts
        feeds = pass_feeds(lines, gear.teeth)
        assert feeds, lines
        for feed, table in feeds:
            h = reference.h_max(gear.module, gear.teeth, gear.helix_angle, 0.0, hob.tip_diameter, hob.gashes,
                                hob.starts, feed)
            assert h <= reference.ALLOWED * (1 + 1e-9), (gear.id, hob.id, feed, h)
            assert feed <= table_rough(gear.module) + 1e-9
            one_step_more = feed + 0.1 / table
            if reference.h_max(gear.module, gear.teeth, gear.helix_angle, 0.0, hob.tip_diameter, hob.gashes,
                               hob.starts, one_step_more) > reference.ALLOWED:
                at_bound += 1
                assert feed < table_rough(gear.module)
    if starts > 1:
        assert at_bound >= 5


def test_gears_alike_but_for_their_helix_each_get_their_own_bound(conn):
    """Two m2 z120 gears of one material and grade, spur and 30° helical, in one batch with a 3-start hob of
    9 gashes: the helical's chips are 1.18× thicker at the same feed (z2^(9.25e-3·β) outgrows the other β
    terms at z 120), so it must not take the spur's feed (the planner shares cutting data between gears alike)."""
    conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, coating, gashes) "
                 "VALUES ('C-HELIX-R', 2, 3, 70, 120, 'R', 'AAA', 'TiN', 9)")   # one hob: both gears' key
    for number, (beta, hand) in enumerate([(0, None), (30, "R")]):
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, "
                     "material, hardness, quality_grade) VALUES (%s, %s, 2, 120, 20, %s, %s, 20, '45', 200, 5)",
                     (82000 + number, "helical" if beta else "spur", beta, hand))
    assert reference.h_max(2, 120, 30, 0, 70, 9, 3, 1.0) > reference.h_max(2, 120, 0, 0, 70, 9, 3, 1.0)
    batch = instantiate_gears(conn, 82000, 82001, choices=Choices(allowance=0.1))
    assert batch.programs == 2
    for (lines,) in conn.execute("SELECT lines FROM program WHERE id BETWEEN %s AND %s",
                                 (batch.first_program_id, batch.last_program_id)).fetchall():
        gear = load_gear(conn, int(next(line.split()[2] for line in lines if line.startswith("; GEAR "))))
        bound = reference.feed_at_bound(2, 120, gear.helix_angle, 0, 70, 9, 3)
        feeds = [feed for feed, _ in pass_feeds(lines, 120)]
        assert max(feeds) <= bound + 1e-9 and max(feeds) > 0.9 * bound, (gear.id, feeds, bound)


def test_a_program_hand_edited_beyond_the_chip_bound_is_refused(conn):
    """Gear 45's program with its rough pass raised by a fifth (still below the §C table's 4.0 mm/rev):
    the simulation refuses that pass, naming the chip bound."""
    program = instantiate_gear(conn, 45, choices=Choices(cuts=2))
    gear, machine = load_gear(conn, 45), load_machine(conn, MACHINE)
    hob = {hob.id: hob for hob in load_hobs(conn)}["H-M4-A-R1"]
    assert not simulate_program(program.lines, gear, hob, machine, "TEST").refusals
    feeds = pass_feeds(program.lines, 25)
    table = feeds[0][1]
    raised = math.floor(1.2 * reference.feed_at_bound(4, 25, 0, 0, 90, 12, 1) * table * 10) / 10
    assert raised / table < 4.0
    lines, done = list(program.lines), False
    for at, line in enumerate(lines):
        if not done and line.startswith("G1") and " Z" in f" {line}" and FEED.search(line):
            lines[at], done = FEED.sub(f"F{raised:.1f}", line), True
    refusals = simulate_program(lines, gear, hob, machine, "TEST").refusals
    assert [r for r in refusals if "Hoffmeister" in r.message and f"F{raised:.1f}" in r.line], refusals


def test_the_hob_csv_round_trips_gashes_and_profile(run, tmp_path):
    """`hobs import` reads gashes and profile, `hobs list --csv` writes them back, `--json` lists them."""
    path = tmp_path / "hobs.csv"
    path.write_text("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,gashes,profile\n"
                    "H-CHIP-1,2,20,3,80,120,R,AA,17,protuberance\n"
                    "H-CHIP-2,3,20,1,90,130,L,A,,\n", encoding="utf-8")
    assert run("hobs", "import", str(path)).exit_code == 0
    listed = {hob["hob_id"]: hob for hob in json.loads(run("hobs", "list", "--json").stdout)["hobs"]}
    assert (listed["H-CHIP-1"]["gashes"], listed["H-CHIP-1"]["profile"]) == (17, "protuberance")
    assert (listed["H-CHIP-2"]["gashes"], listed["H-CHIP-2"]["profile"]) == (12, "standard")   # the defaults
    exported = run("hobs", "list", "--csv").stdout
    header = exported.splitlines()[0].split(",")
    assert header[-2:] == ["gashes", "profile"]
    again = tmp_path / "again.csv"
    again.write_text(exported, encoding="utf-8")
    assert run("hobs", "import", str(again)).exit_code == 0
    relisted = {hob["hob_id"]: hob for hob in json.loads(run("hobs", "list", "--json").stdout)["hobs"]}
    assert relisted == listed


@pytest.mark.parametrize("cells, problem", [("0,standard", "gashes"), ("12,sharp", "profile")])
def test_a_bad_gash_count_or_profile_is_refused(read_only_run, tmp_path, cells, problem):
    path = tmp_path / "hobs.csv"
    path.write_text("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,gashes,profile\n"
                    f"H-CHIP-3,2,20,1,70,100,R,AA,{cells}\n", encoding="utf-8")
    result = read_only_run("hobs", "import", str(path))
    assert result.exit_code != 0 and problem in result.output
