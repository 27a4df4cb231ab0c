"""The search before a refusal (issue 29): a gear the first choice (climb, the best hob, the cuts by
module) does not fit is made with the first alternative that is proved: another feed direction,
another hob that matches, two cuts; a choice the user gave is kept; a gear nothing fits is refused
in one line naming every choice tried, nothing stored; a batch (with workers) does the same.

The layouts are the seeded duplex gear 54 (m2, unit 1 z30 Ø64 b20 at Z0, unit 2 z19 Ø42/Ø33 b15)
with unit 2 moved up. Whether a feed direction fits is computed here from the geometry (reference
§B7, design notes §7): cutting unit 2 (below unit 1), climb enters above unit 2's top face, toward
unit 1, so the run-in E = √(h·(d_a0 − h)) + 2 mm must fit between the faces besides the hob's reach
into unit 1; conventional leaves toward unit 1 and its run-out may be shortened to a millimetre
past the face. The reach is a lower bound: the unswivelled hob's tip circle (radius r0 about the
cut's centre distance a = (d_f + d_a0)/2) inside unit 1's tip radius plus the 1 mm clearance,
√(r0² − (a − r1)²)."""
from __future__ import annotations

import math

import psycopg
import pytest
from helpers.nc_reader import read_program

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear, instantiate_gears
from engine.programs.options import RunMode

GEAR = 54
UNIT_1 = {"tip": 64.0, "b": 20.0}
UNIT_2 = {"tip": 42.0, "root": 33.0, "b": 15.0}
CLEARANCE = 1.0        # mm the engine keeps between the hob and the other unit (design notes §7)
SAFETY = 2.0           # mm added to the run-in (§B7: 1–3 mm)
GAP_CONVENTIONAL = 40.0   # mm between the faces: conventional fits, climb does not (computed below)
GAP_NONE = 10.0           # mm: nothing fits


def reach_into_unit_1(hob_tip: float) -> float:
    """Lower bound of how far along Z the hob cutting unit 2 reaches into unit 1 (+ clearance)."""
    r0, centre = hob_tip / 2, (UNIT_2["root"] + hob_tip) / 2
    inside = centre - (UNIT_1["tip"] / 2 + CLEARANCE)
    return math.sqrt(r0 ** 2 - inside ** 2) if inside < r0 else 0.0


def run_in(hob_tip: float) -> float:
    """§B7: E = √(h·(d_a0 − h)) + safety, h the full tooth depth of unit 2."""
    depth = (UNIT_2["tip"] - UNIT_2["root"]) / 2
    return math.sqrt(depth * (hob_tip - depth)) + SAFETY


def move_unit_2(conn, gap: float) -> None:
    conn.execute("UPDATE gear_unit SET z_top = %s WHERE gear_id = %s", (-UNIT_1["b"] - gap, GEAR))


def library(conn) -> list[tuple[str, float]]:
    """The hobs of the library for gear 54 (module 2, 20°, grade 8: class A or better), R first
    (the gear has no hand: R preferred), then the coarsest class, then the id (hob matching)."""
    rows = conn.execute("SELECT id, tip_diameter, hand, accuracy_class FROM hob WHERE module = 2 "
                        "AND pressure_angle = 20 AND purpose = 'cylindrical' AND accuracy_class IN ('A', 'AA', "
                        "'AAA')").fetchall()
    rows.sort(key=lambda row: (row[2] != "R", -("AAA", "AA", "A").index(row[3]), row[0]))
    return [(row[0], float(row[1])) for row in rows]


def stored_jobs(conn) -> int:
    return conn.execute("SELECT count(*) FROM job").fetchone()[0]


def unit_2_passes(program) -> list:
    """The axial passes (G1 in Z only) below unit 1's bottom face: unit 2's."""
    nc = read_program(program.text)
    return [m for m in nc.moves_in("G1") if m.changed == {"Z"} and max(m.start["Z"], m.end["Z"]) < -UNIT_1["b"]]


def test_the_layout_is_one_climb_cannot_cut_and_conventional_can():
    """The physics of the test layout, independent of the engine: with every seeded m2 hob
    (d_a0 70) climb needs more than the gap, conventional (a run-out of 1 mm) less."""
    reach = reach_into_unit_1(70.0)
    assert run_in(70.0) + CLEARANCE + reach > GAP_CONVENTIONAL > 1.0 + CLEARANCE + reach


def test_a_duplex_gear_climb_does_not_fit_is_cut_conventional_and_says_why(conn):
    move_unit_2(conn, GAP_CONVENTIONAL)
    program = instantiate_gear(conn, GEAR)
    hob = library(conn)[0][0]
    passes = unit_2_passes(program)
    assert passes and all(m.end["Z"] > m.start["Z"] for m in passes), "conventional feeds up"
    note = next(note for note in program.notes if "not the first choice" in note)
    assert f"cut with [conventional, hob {hob}, 1 cut]" in note
    assert f"[climb, hob {hob}, 1 cut] does not fit" in note and "unit 1" in note
    job = conn.execute("SELECT params->>'feed_mode', hob_id, cutting->>'choice' FROM job WHERE id = %s",
                       (program.job_id,)).fetchone()
    assert job == ("conventional", hob, note)   # stored: proved by the verifier and the simulation
    top = max(max(m.start["Z"], m.end["Z"]) for m in passes)
    assert top <= -UNIT_1["b"] - CLEARANCE - reach_into_unit_1(70.0) + 0.001, "the hob stays clear of unit 1"


def test_the_first_choice_that_fits_is_taken_without_a_note(conn):
    program = instantiate_gear(conn, GEAR)   # the seeded layout: climb fits
    assert not any("first choice" in note for note in program.notes)
    assert all(m.end["Z"] < m.start["Z"] for m in unit_2_passes(program)), "climb feeds down"


def add_small_hob(conn) -> str:
    """An m2 hob of d_a0 40 (class A, hand L): climb fits the 40 mm gap with it (computed)."""
    assert run_in(40.0) + CLEARANCE + reach_into_unit_1(40.0) + 1.0 < GAP_CONVENTIONAL
    conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class) "
                 "VALUES ('H-M2-A-L1-D40', 2, 1, 40, 60, 'L', 'A')")
    return "H-M2-A-L1-D40"


def test_a_feed_mode_the_user_gave_is_kept_and_another_hob_taken(conn):
    move_unit_2(conn, GAP_CONVENTIONAL)
    small = add_small_hob(conn)
    assert small in [hob for hob, _ in library(conn)[:3]], "a hob the search tries"
    program = instantiate_gear(conn, GEAR, choices=Choices(feed_mode="climb"))
    assert all(m.end["Z"] < m.start["Z"] for m in unit_2_passes(program)), "climb, as given"
    assert f"; HOB {small}" in "\n".join(program.lines)
    note = next(note for note in program.notes if "not the first choice" in note)
    assert f"cut with [climb (given), hob {small}, 1 cut]" in note and "conventional" not in note


def test_a_feed_mode_the_user_gave_is_named_in_the_refusal(conn):
    move_unit_2(conn, GAP_CONVENTIONAL)
    before = stored_jobs(conn)
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, GEAR, choices=Choices(feed_mode="climb"))
    message = str(refused.value)
    assert "\n" not in message and message.endswith("nothing stored")
    assert "conventional" not in message, "a feed mode the user gave is never changed"
    for hob, _ in library(conn):
        assert f"[climb (given), hob {hob}, 1 cut]" in message and f"[climb (given), hob {hob}, 2 cuts]" in message
    assert stored_jobs(conn) == before


def expected_choices(conn) -> list[str]:
    """Every choice of the search for gear 54 (m2: one cut by module, §B14): one cut climb and
    conventional (a single cut runs the roughing direction: conventional-climb is conventional),
    two cuts in all three modes, each then with the units fed each their own way (a cluster
    gear: unit 1's/unit 2's); with every hob of the library that matches."""
    hobs = [hob for hob, _ in library(conn)]
    per_unit = ("climb/conventional", "conventional/climb")
    one = [f"[{mode}, hob {hob}, 1 cut]" for hob in hobs for mode in ("climb", "conventional", *per_unit)]
    two = [f"[{mode}, hob {hob}, 2 cuts]" for hob in hobs
           for mode in ("climb", "conventional", "conventional-climb", *per_unit)]
    return one + two


def test_a_gear_nothing_fits_is_refused_naming_every_choice_tried(conn):
    move_unit_2(conn, GAP_NONE)
    assert 1.0 + CLEARANCE + reach_into_unit_1(70.0) > GAP_NONE, "no direction fits the gap"
    before = stored_jobs(conn)
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, GEAR)
    message = str(refused.value)
    assert "\n" not in message and message.startswith(f"gear {GEAR}: ") and message.endswith("nothing stored")
    positions = [message.find(said) for said in expected_choices(conn)]
    assert -1 not in positions, message
    assert positions == sorted(positions), "in the order of the search"
    assert message.count("[") == len(expected_choices(conn)), "nothing else tried"
    # one reason per kind of cut (a single cut, a rough cut), each said once, not once per choice
    assert message.count("reaches") == 2 and message.count("use a smaller hob") == 2, message
    assert stored_jobs(conn) == before


def test_the_cli_refuses_with_exit_1_and_stores_nothing(run):
    with psycopg.connect(run.url) as conn:
        move_unit_2(conn, GAP_NONE)
        expected = expected_choices(conn)
    refused = run("instantiate", "--gear", str(GEAR))
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert all(said in refused.stderr for said in expected)
    with psycopg.connect(run.url) as conn:
        assert stored_jobs(conn) == 0


@pytest.mark.parametrize("workers", [1, 2])
def test_a_batch_takes_the_same_choice(conn, workers):
    move_unit_2(conn, GAP_CONVENTIONAL)
    alone = instantiate_gear(conn, GEAR, mode=RunMode(dry_run=True))
    batch = instantiate_gears(conn, 53, GEAR, mode=RunMode(dry_run=True, workers=workers))
    assert batch.programs == 2
    assert [note for note in batch.notes if note.startswith(f"GEAR{GEAR}: ")] == \
        [f"GEAR{GEAR}: {note}" for note in alone.notes]


def test_a_batch_names_the_refusal_with_every_choice_tried(run):
    with psycopg.connect(run.url) as conn:
        move_unit_2(conn, GAP_NONE)
        expected = expected_choices(conn)
    refused = run("instantiate", "--gears", f"53-{GEAR}", "--workers", "2")
    assert refused.exit_code == 1
    line = next(line for line in refused.stderr.splitlines() if f"gear {GEAR}:" in line)
    assert all(said in line for said in expected)
    with psycopg.connect(run.url) as conn:
        assert stored_jobs(conn) == 0


def test_a_job_the_search_made_is_made_again_as_it_was(conn):
    """A stored job keeps the choice taken (feed mode, hob, cut count): made again, the same program."""
    from engine.programs.remake import instantiate_job

    move_unit_2(conn, GAP_CONVENTIONAL)
    program = instantiate_gear(conn, GEAR, choices=Choices(cuts=2))   # two cuts given on an m2 gear
    again = instantiate_job(conn, program.job_id)
    def body(lines):   # all but the lineage line (it names the program id)
        return [line for line in lines if not line.startswith("; PROGRAM ")]

    assert body(again.lines) == body(program.lines)


def test_a_refusal_keeps_its_type_and_one_choice_keeps_its_words():
    """Nothing fits: the refusal is of the first refusal's type (a verifier's LimitError stays one);
    a search of one choice only (everything given, one hob) refuses with the words of that refusal."""
    from engine.gears.records import Hob
    from engine.programs.job_search import attempts, first_that_fits
    from engine.verifier import LimitError

    hobs = [Hob(f"H{n}", 2.0, 20.0, 1, 70.0, 100.0, "R", "A", "HSS", "TiN", "cylindrical") for n in (1, 2)]

    def too_fast(attempt):
        raise LimitError(f"gear 7: the table turns too fast with {attempt.hob.id}; nothing stored")

    with pytest.raises(LimitError) as refused:
        first_that_fits(7, 2.0, attempts(hobs, Choices(), 2.0), too_fast)
    assert str(refused.value).startswith("gear 7: no choice fits: the first choice [climb, hob H1, 1 cut] "
                                         "the table turns too fast with H1; also tried, in order: "
                                         "(a) [conventional, hob H1, 1 cut], [climb, hob H2, 1 cut]")
    assert str(refused.value).count("too fast") == 1, "a reason alike but for its numbers is said once"
    with pytest.raises(LimitError) as alone:
        first_that_fits(7, 2.0, attempts(hobs[:1], Choices(feed_mode="climb", cuts=1), 2.0), too_fast)
    assert str(alone.value) == "gear 7: the table turns too fast with H1; nothing stored"


def test_a_row_that_fails_to_run_is_not_searched_around(conn):
    """A template row that fails to evaluate fails for every choice: the search stops at it, names the
    row once and tries nothing else (a hostile row's refusal ran past 700 characters, repeated per choice)."""
    conn.execute("INSERT INTO template_view (gear_class, id, t, n, s) VALUES ('spur', 750, 'main', 1, %s)",
                 ("broken = 1 / (z2 - z2)",))
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, 42, mode=RunMode(draft=True))
    message = str(refused.value)
    assert "row 750" in message and "tried" not in message and message.count("row 750") == 1
