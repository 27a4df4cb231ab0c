"""Cutting data from the machining history: the paper's example comes back as published,
the nearest case wins, cases transfer to another hob through the cutting speed, no cases
means the reference defaults, and a confirmed job becomes a case exactly once."""
import csv
import json
import math

import pytest
from helpers import chip_reference, feed_mark_reference
from msgspec.structs import replace
from psycopg import sql

from engine.errors import EngineError
from engine.gears.case_base import job_cutting_record
from engine.gears.cases import confirm_job, list_cases, seed_cases, suggest
from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.paths import SEED_DIR
from engine.programs.instantiate import instantiate_gear

PAPER_GEAR = 9019
# The published example: m 2, α 20°, z 19, d_a 42.5, 40Cr, grade 7, cone 6.5°, 1-start AA hob, rough cut.
PAPER_N0, PAPER_AXIAL, PAPER_RADIAL = 246, 105.0, 36.0
# Reference §C: roughing f_a for m2 is 1.5–3.0 mm per workpiece rev; the paper's is 105/(246/19) = 8.11.
M2_ROUGH_MAX = 3.0
PAPER_FEED_PER_REV = PAPER_AXIAL / (PAPER_N0 / 19)
BOUNDED_AXIAL = round(M2_ROUGH_MAX * PAPER_N0 / 19, 1)                                     # 38.8 mm/min
BOUNDED_RADIAL = round(PAPER_RADIAL * M2_ROUGH_MAX / PAPER_FEED_PER_REV, 1)                # scaled alike
# The job's single cut is its last: its feed marks at 3.0 mm/rev (§B6) are deeper than grade 7 allows on
# m2 z19 b20 with d_a0 70, so the job cuts at the bound (the suggestion, per cut kind, does not know the
# job's cut count and is bounded by §C alone).
JOB_AXIAL = round(min(M2_ROUGH_MAX, feed_mark_reference.bound(7, 2, 19, 0, 20, 20, 70)) * PAPER_N0 / 19, 1)
# A case within the §C range even for a 2-start hob (3.0/√2 = 2.12): 25 mm/min is 1.93 mm/rev.
USUAL_AXIAL, USUAL_RADIAL = 25.0, 8.0
CASE_COLUMNS = ("module", "teeth", "material", "hardness", "quality_grade", "hob_material", "hob_coating",
                "hob_starts", "hob_tip_diameter", "cut", "hob_speed", "axial_feed", "radial_feed", "source")


def insert_paper_gear(conn, gear_id=PAPER_GEAR, teeth=19):
    # class spur, so no cone: the class and the cone do not enter the distance, and the simulation holds a
    # program to the gear's cone (a spur program for a conical record leaves the cone's root uncut)
    # d_f 33.5: d_a 42.5 read as a profile shift x = +0.125 (reference §D)
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, face_width, tip_diameter, "
                 "root_diameter, material, hardness, quality_grade) "
                 "VALUES (%s, 'spur', 2, %s, 20, 20, 42.5, 33.5, '40Cr', 250, 7)", (gear_id, teeth))
    return load_gear(conn, gear_id)


def hob(conn, hob_id="H-M2-AA-R1", **changes):
    return replace(next(h for h in load_hobs(conn) if h.id == hob_id), **changes)


def insert_case(conn, **values):
    row = {"module": 2, "teeth": 19, "material": "40Cr", "hardness": 250, "quality_grade": 7, "hob_material": "HSS",
           "hob_coating": "TiN", "hob_starts": 1, "hob_tip_diameter": 70, "cut": "rough",
           "hob_speed": PAPER_N0, "axial_feed": PAPER_AXIAL, "radial_feed": PAPER_RADIAL, "source": "test"} | values
    query = sql.SQL("INSERT INTO cutting_case ({}) VALUES ({}) RETURNING id").format(
        sql.SQL(", ").join(map(sql.Identifier, CASE_COLUMNS)), sql.SQL(", ").join(map(sql.Placeholder, CASE_COLUMNS)))
    return conn.execute(query, row).fetchone()[0]


def mm_per_min(feed_per_rev, cutting, starts=1, teeth=19):
    """§B5: v_f = f·n0·z0/z2."""
    return round(feed_per_rev * cutting.hob_speed * starts / teeth, 1)


@pytest.fixture
def machine(conn):
    return load_machine(conn, "hobber-840d")


@pytest.fixture
def empty_history(conn):
    conn.execute("DELETE FROM cutting_case")
    return conn


def test_the_papers_example_comes_back_with_its_feed_bounded_to_the_m2_roughing_maximum(conn, machine):
    seed_cases(conn)
    gear = insert_paper_gear(conn)
    suggestion = suggest(conn, gear, hob(conn), machine)
    cutting = suggestion.cutting
    assert cutting.hob_speed == PAPER_N0
    assert math.isclose(cutting.cutting_speed, math.pi * 70 * 246 / 1000)
    nearest = suggestion.cases[suggestion.cases.cut == "rough"].iloc[0]
    assert nearest.source.startswith("CAO/YAN/GUO 2015") and nearest.distance == 0
    # Reference §D: 105 mm/min at n2 = 246/19 r/min is 8.11 mm per workpiece rev, 2.7× the 3.0 for m2 (§C):
    # bounded to 3.0, the radial feed scaled by the same factor, and said in one note.
    assert mm_per_min(cutting.axial_feed_rough, cutting) == BOUNDED_AXIAL
    assert mm_per_min(cutting.radial_feed, cutting) == BOUNDED_RADIAL
    feed_note = [note for note in suggestion.notes if f"{PAPER_FEED_PER_REV:.2f}" in note]
    assert len(feed_note) == 1 and "bounded to 3.00" in feed_note[0] and "m2" in feed_note[0]


@pytest.mark.parametrize("module, teeth, starts, cut, table", [
    (1.0, 20, 1, "rough", 2.0), (1.5, 20, 1, "rough", 2.5), (2.5, 30, 1, "rough", 3.25), (4.0, 25, 1, "rough", 4.0),
    (3.0, 41, 1, "finish", 2.0), (1.5, 20, 1, "finish", 1.25), (0.8, 20, 1, "rough", 2.0),
    (2.0, 30, 2, "rough", 3.0), (2.0, 30, 4, "finish", 1.5), (2.0, 30, 3, "rough", 3.0)])
def test_a_case_feed_above_the_table_is_bounded_per_module_and_chip(empty_history, machine, module, teeth,
                                                                    starts, cut, table):
    """§C table interpolated between modules (m1 2.0/1.0, m2 3.0/1.5, m3 3.5/2.0, m4 4.0/2.0), the end rows
    beyond; and at most the feed whose Hoffmeister chip stays within 0.20 mm (§C1: the seeded hob's d_a0 70
    and 12 gashes, z0 as given). A case of 6 mm/rev is above all of them."""
    conn = empty_history
    maximum = min(table, chip_reference.feed_at_bound(module, teeth, 0.0, 0.0, 70.0, 12, starts))
    insert_case(conn, module=module, teeth=teeth, hob_starts=starts, cut=cut,
                axial_feed=6.0 * PAPER_N0 * starts / teeth, radial_feed=2.0 * PAPER_N0 * starts / teeth)
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, material, hardness, quality_grade) "
                 "VALUES (9020, 'spur', %s, %s, 20, '40Cr', 250, 7)", (module, teeth))
    suggestion = suggest(conn, load_gear(conn, 9020), hob(conn, module=module, starts=starts), machine)
    feed = suggestion.feeds(cut)
    assert feed["axial_feed_per_rev"] == pytest.approx(maximum)
    assert feed["radial_feed_per_rev"] == pytest.approx(2.0 * maximum / 6.0)
    assert sum(f"bounded to {maximum:.2f}" in note and note.startswith(cut) for note in suggestion.notes) == 1


def test_a_case_feed_within_the_table_is_taken_as_is_without_a_note(empty_history, machine):
    conn = empty_history
    insert_case(conn, axial_feed=USUAL_AXIAL, radial_feed=USUAL_RADIAL)
    suggestion = suggest(conn, insert_paper_gear(conn), hob(conn), machine)
    assert mm_per_min(suggestion.cutting.axial_feed_rough, suggestion.cutting) == USUAL_AXIAL
    assert not [note for note in suggestion.notes if "bounded" in note]


def test_an_override_of_the_feed_beyond_the_table_is_refused(empty_history, machine):
    from engine.gears.cutting_data import default_cutting_data

    cutting = default_cutting_data(2.0, "40Cr", True, 70, 1000)
    gear = insert_paper_gear(empty_history)
    given = cutting.with_overrides(gear, hob(empty_history), axial_feed_rough=M2_ROUGH_MAX)
    assert given.axial_feed_rough == M2_ROUGH_MAX
    with pytest.raises(EngineError, match="axial feed rough 3.1 mm per workpiece rev exceeds the 3.00 mm/rev "
                                          "roughing maximum for m2"):
        cutting.with_overrides(gear, hob(empty_history), axial_feed_rough=3.1)


def test_the_nearest_case_ranks_first_and_weighs_most(empty_history, machine):
    conn = empty_history
    near = insert_case(conn, teeth=21, hob_speed=300, axial_feed=30, radial_feed=10)
    far = insert_case(conn, module=3, teeth=40, material="45", hardness=200, quality_grade=8,
                      hob_speed=200, axial_feed=20, radial_feed=8)
    gear = insert_paper_gear(conn)
    suggestion = suggest(conn, gear, hob(conn), machine, top=2)
    rough = suggestion.cases[suggestion.cases.cut == "rough"]
    assert list(rough.id) == [near, far] and 0 < rough.distance.iloc[0] < rough.distance.iloc[1]
    v_near, v_far = math.pi * 70 * 300 / 1000, math.pi * 70 * 200 / 1000
    assert abs(suggestion.cutting.cutting_speed - v_near) < abs(suggestion.cutting.cutting_speed - v_far)
    assert suggestion.proposals["rough"].case_ids == (near, far)


@pytest.mark.parametrize("tip_diameter", [50.0, 80.0, 90.0])
def test_a_case_transfers_to_another_hob_through_the_cutting_speed(empty_history, machine, tip_diameter):
    conn = empty_history
    insert_case(conn, axial_feed=USUAL_AXIAL, radial_feed=USUAL_RADIAL)   # a cut made with a d_a0 70 hob
    gear = insert_paper_gear(conn)
    cutting = suggest(conn, gear, hob(conn, tip_diameter=tip_diameter), machine).cutting
    # Same v = π·70·246/1000 on the other hob: n0 = 246·70/d_a0; same feed per workpiece rev.
    expected_n0 = round(PAPER_N0 * 70 / tip_diameter)
    assert cutting.hob_speed == expected_n0
    assert mm_per_min(cutting.axial_feed_rough, cutting) == round(USUAL_AXIAL * expected_n0 / PAPER_N0, 1)
    assert mm_per_min(cutting.radial_feed, cutting) == round(USUAL_RADIAL * expected_n0 / PAPER_N0, 1)


def test_feeds_per_workpiece_rev_carry_over_to_other_teeth_and_starts(empty_history, machine):
    conn = empty_history
    insert_case(conn, axial_feed=USUAL_AXIAL, radial_feed=USUAL_RADIAL)
    gear = insert_paper_gear(conn, teeth=38)
    cutting = suggest(conn, gear, hob(conn, starts=2), machine).cutting
    # f = 25/(246·1/19) mm/rev; on z 38 with 2 starts: v_f = f·246·2/38 = 25 mm/min again.
    assert cutting.hob_speed == PAPER_N0
    assert mm_per_min(cutting.axial_feed_rough, cutting, starts=2, teeth=38) == USUAL_AXIAL


def test_the_hob_speed_stops_at_the_spindle_maximum(empty_history, machine):
    conn = empty_history
    insert_case(conn)
    slow_machine = replace(machine, spindle_max=200)
    suggestion = suggest(conn, insert_paper_gear(conn), hob(conn), slow_machine)
    assert suggestion.cutting.hob_speed == 200
    assert any("capped" in note and "200" in note for note in suggestion.notes)


def test_without_cases_the_reference_defaults_are_proposed(empty_history, machine):
    conn = empty_history
    suggestion = suggest(conn, insert_paper_gear(conn), hob(conn), machine)
    cutting = suggestion.cutting
    # §C: 40Cr with a coated HSS hob, 50–90 m/min (the defaults take 70); m2 feeds 2.5 rough, 1.2 finish.
    assert cutting.cutting_speed == 70.0 and cutting.hob_speed == round(1000 * 70 / (math.pi * 70))
    assert (cutting.axial_feed_rough, cutting.axial_feed_finish) == (2.5, 1.2)
    assert "no cases" in cutting.source and "defaults" in cutting.source and suggestion.cases.empty


def test_a_cut_kind_without_cases_falls_back_alone(empty_history, machine):
    conn = empty_history
    insert_case(conn)
    cutting = suggest(conn, insert_paper_gear(conn), hob(conn), machine).cutting
    assert cutting.hob_speed == PAPER_N0 and cutting.axial_feed_finish == 1.2
    assert "finish: no cases, defaults" in cutting.source


def insert_job(conn, gear, hob_, cutting_record):
    return conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params, cutting) "
                        "VALUES (%s, %s, 'hobber-840d', %s, '{}', %s) RETURNING id",
                        (gear.id, gear.gear_class, hob_.id, json.dumps(cutting_record))).fetchone()[0]


def test_a_confirmed_job_becomes_one_case_per_cut_and_only_once(conn, machine):
    seed_cases(conn)
    gear, paper_hob = insert_paper_gear(conn), hob(conn)
    suggestion = suggest(conn, gear, paper_hob, machine)
    record = job_cutting_record(suggestion.cutting, gear, paper_hob, ["rough"], suggestion.case_ids(["rough"]))
    assert record["rough"] == {"axial_feed": BOUNDED_AXIAL, "radial_feed": BOUNDED_RADIAL} and "finish" not in record
    job_id = instantiate_gear(conn, gear.id).job_id   # a job becomes a case only once the engine made its program
    stored = stored_cutting(conn, job_id)
    assert (stored["hob_speed"], stored["rough"], "finish" in stored) == (
        PAPER_N0, {"axial_feed": JOB_AXIAL, "radial_feed": BOUNDED_RADIAL}, False)
    before = len(list_cases(conn))
    (case_id,) = confirm_job(conn, job_id)
    case = list_cases(conn).set_index("id").loc[case_id]
    assert (case.module, case.teeth, case.material, case.cut, case.hob_tip_diameter) == (2, 19, "40Cr", "rough", 70)
    assert (case.hob_speed, case.axial_feed, case.radial_feed) == (PAPER_N0, JOB_AXIAL, BOUNDED_RADIAL)
    assert case.source == f"job {job_id}" and case.job_id == job_id
    with pytest.raises(EngineError, match=f"job {job_id} was already confirmed at"):
        confirm_job(conn, job_id)
    assert len(list_cases(conn)) == before + 1


def test_a_two_cut_job_gives_a_rough_and_a_finish_case(conn, machine):
    gear, paper_hob = insert_paper_gear(conn), hob(conn)
    cutting = suggest(conn, gear, paper_hob, machine).cutting
    job_id = instantiate_gear(conn, gear.id, choices=Choices(cuts=2)).job_id
    ids = confirm_job(conn, job_id)
    cases = list_cases(conn).set_index("id").loc[ids]
    assert list(cases.cut) == ["rough", "finish"]
    assert cases.axial_feed.iloc[1] == mm_per_min(cutting.axial_feed_finish, cutting)


def stored_cutting(conn, job_id):
    return conn.execute("SELECT cutting FROM job WHERE id = %s", (job_id,)).fetchone()[0]


def test_confirm_refuses_what_cannot_become_a_case(conn):
    gear, paper_hob = insert_paper_gear(conn), hob(conn)
    with pytest.raises(EngineError, match="job 987654 does not exist"):
        confirm_job(conn, 987654)
    job_id = insert_job(conn, gear, paper_hob, {})
    with pytest.raises(EngineError, match=f"job {job_id} has no cutting data"):
        confirm_job(conn, job_id)


def seed_file_rows():
    with (SEED_DIR / "cases.csv").open(encoding="utf-8", newline="") as file:
        return list(csv.DictReader(file))


def test_seeding_the_cases_adds_only_what_is_missing(empty_history):
    conn = empty_history
    rows = seed_file_rows()
    assert seed_cases(conn) == len(rows)
    assert seed_cases(conn) == 0 and len(list_cases(conn)) == len(rows)
    conn.execute("DELETE FROM cutting_case WHERE source LIKE 'CAO%%'")
    assert seed_cases(conn) == 1


def test_the_seed_holds_the_paper_case_alone_at_its_features():
    rows = seed_file_rows()
    paper = [r for r in rows if (r["module"], r["teeth"], r["material"], r["quality_grade"], r["cut"])
             == ("2", "19", "40Cr", "7", "rough")]
    assert len(paper) == 1 and paper[0]["source"].startswith("CAO/YAN/GUO 2015")
    assert (paper[0]["hob_speed"], paper[0]["axial_feed"], paper[0]["radial_feed"]) == ("246", "105", "36")
    assert {r["cut"] for r in rows} == {"rough", "finish"}
    assert {"45", "20CrMnTi", "40Cr"} <= {r["material"] for r in rows}




def test_cli_suggest_prints_the_hob_cases_and_proposal(read_only_run):
    result = read_only_run("suggest", "--gear", 42)   # the seeded spur gear with the paper's data
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "H-M2-AA-R1" in out and "CAO/YAN/GUO 2015" in out
    assert "n0 246 r/min" in out and f"axial {BOUNDED_AXIAL} mm/min (3.00 mm/rev)" in out
    assert f"radial {BOUNDED_RADIAL} mm/min" in out
    bounded = [line for line in out.splitlines() if "bounded to" in line]
    assert len(bounded) == 1 and "8.11" in bounded[0] and "3.00" in bounded[0] and "m2" in bounded[0]
    report = json.loads(read_only_run("suggest", "--gear", 42, "--json", "--top", 1).stdout)
    assert report["hob"]["hob_id"] == "H-M2-AA-R1" and report["hob_speed"] == PAPER_N0
    assert (report["rough"]["axial_feed"], report["rough"]["radial_feed"]) == (BOUNDED_AXIAL, BOUNDED_RADIAL)
    assert len(report["cases"]) == 2


@pytest.mark.parametrize("args, words", [
    (("suggest", "--gear", 999), ("gear 999", "does not exist")),
    (("cases", "confirm", "--job", 999), ("job 999", "does not exist")),
    (("suggest", "--gear", 42, "--machine", "lathe-iso"), ("lathe-iso", "not a hobbing machine")),
])
def test_cli_errors_are_one_line(run, args, words):
    result = run(*args)
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and all(word in message for word in words)


def test_cli_confirm_adds_cases_once_and_list_shows_them(run):
    job_id = json.loads(run("instantiate", "--gear", 42, "--json").stdout)["job_id"]
    listed = json.loads(run("cases", "list", "--json").stdout)["cases"]
    assert len(listed) == len(seed_file_rows())
    result = run("cases", "confirm", "--job", job_id)
    assert result.exit_code == 0 and f"job {job_id} confirmed" in result.stdout
    again = run("cases", "confirm", "--job", job_id)
    assert again.exit_code == 1 and "already confirmed" in again.stderr
    listed = json.loads(run("cases", "list", "--json").stdout)["cases"]
    assert [c["source"] for c in listed].count(f"job {job_id}") == 1
