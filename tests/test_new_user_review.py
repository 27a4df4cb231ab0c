"""A new user's review (issue 29): a gear classed spur before its unit 2 was imported, a third
unit, work-holdings refused row by row and in plain words, and a hob's gashes. Each refusal is
one line, exit 1, and leaves the database as it was."""
from __future__ import annotations

import json

import psycopg
import pytest

from engine.errors import EngineError
from engine.gears.holding_matching import HEIGHT_MARGIN, choose_holding
from engine.gears.records import Gear, Hob
from engine.machines.records import load_machine
from engine.machines.work_holding import WorkHolding

GEAR_ID = 95001
# m2 z30 spur, b 20, no class named: the tree gives spur (no units, no cone, no crowning, β 0).
GEARS = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,material,hardness,"
         f"quality_grade,quantity\n{GEAR_ID},,2,30,20,0,,20,40Cr,220,8,10\n")
UNIT_HEADER = "gear_id,unit,teeth,face_width,z_top\n"
UNIT_2 = f"{GEAR_ID},2,20,15,-45\n"       # z 20 under the first unit's face (Z −20) with a 25 mm gap


def execute(url: str, query: str, args: tuple = ()) -> list[tuple]:
    with psycopg.connect(url) as conn:
        cursor = conn.execute(query, args)
        return cursor.fetchall() if cursor.description else []


def write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def spur_gear(run, tmp_path):
    """Gear 95001 imported without a class (the tree gives spur)."""
    result = run("gears", "import", write(tmp_path, "gears.csv", GEARS))
    assert result.exit_code == 0, result.output
    assert execute(run.url, "SELECT gear_class FROM gear WHERE id = %s", (GEAR_ID,)) == [("spur",)]
    return run


def test_a_unit_for_a_spur_gear_says_what_to_do_and_replace_classes_it_duplex(spur_gear, tmp_path):
    run = spur_gear
    added = run("gears", "units", write(tmp_path, "units.csv", UNIT_HEADER + UNIT_2))
    assert added.exit_code == 0, added.output
    assert (f"gear {GEAR_ID}: class spur does not cut further units; give gear_class duplex (or leave it empty: "
            "the tree classes it duplex)") in added.stdout
    explained = run("classify", "--gear", GEAR_ID)
    assert explained.exit_code == 0, explained.output
    assert "explicitly" not in explained.stdout
    assert "class spur is the tree's for the gear without its further units" in explained.stdout
    again = run("gears", "import", tmp_path / "gears.csv", "--replace")   # gear_class still empty
    assert again.exit_code == 0, again.output
    assert f"gear {GEAR_ID}: gear_class spur → duplex" in again.stdout
    assert execute(run.url, "SELECT gear_class FROM gear WHERE id = %s", (GEAR_ID,)) == [("duplex",)]
    explained = run("classify", "--gear", GEAR_ID)
    assert explained.stdout.splitlines()[0] == f"gear {GEAR_ID}: class duplex"
    assert "named class" not in explained.stdout and "tree's for the gear without" not in explained.stdout


def test_a_gear_named_helical_in_the_file_is_still_said_to_be_named(run, tmp_path):
    text = GEARS.replace(f"{GEAR_ID},,2,30,20,0,", f"{GEAR_ID},helical,2,30,20,0,")
    assert run("gears", "import", write(tmp_path, "gears.csv", text)).exit_code == 0
    explained = run("classify", "--gear", GEAR_ID)
    assert "the gear file named class helical explicitly (the tree alone gives spur)" in explained.stdout


def test_units_for_a_gear_with_stored_programs_are_refused_and_nothing_stored(spur_gear, tmp_path):
    """Issue 31: its programs were proved on the gear without units; the units would change their inputs."""
    run = spur_gear
    made = run("instantiate", "--gear", GEAR_ID, "--json")
    assert made.exit_code == 0, made.output
    refused = run("gears", "units", write(tmp_path, "units.csv", UNIT_HEADER + UNIT_2))
    assert refused.exit_code == 1, refused.output
    tip = 2 * 20 + 2 * 2          # d + 2·m of unit 2 (m 2, z 20)
    root = tip - 2 * 2.25 * 2     # a tooth depth 2.25·m below, on each side
    assert (f"gear {GEAR_ID}: the file changes its further units (none) → unit 2 (z 20, b 15, da {tip:g}, "
            f"df {root:g}, z_top -45), but job {json.loads(made.stdout)['job_id']} was made from it; nothing "
            "imported") in refused.stderr
    assert execute(run.url, "SELECT count(*) FROM gear_unit WHERE gear_id = %s", (GEAR_ID,)) == [(0,)]


def test_a_third_unit_is_refused_in_one_line_and_nothing_stored(spur_gear, tmp_path):
    run = spur_gear
    before = execute(run.url, "SELECT * FROM gear_unit ORDER BY gear_id, unit")
    result = run("gears", "units", write(tmp_path, "units.csv", UNIT_HEADER + UNIT_2 + f"{GEAR_ID},3,18,12,-70\n"))
    assert result.exit_code == 1
    assert "line 3, column unit: 3 must be 2: unit 1 is the gear row" in result.stderr, result.stderr
    assert "cuts two per set-up; write 2, and cut a third toothing in a set-up of its own" in result.stderr
    assert execute(run.url, "SELECT * FROM gear_unit ORDER BY gear_id, unit") == before


def test_a_duplex_gear_with_three_units_is_told_to_cut_two_per_setup(run, tmp_path):
    """Units stored before unit 3 was refused (here by SQL): instantiate names the set-up, not an import."""
    text = GEARS.replace(f"{GEAR_ID},,2,30,", f"{GEAR_ID},duplex,2,30,")
    assert run("gears", "import", write(tmp_path, "gears.csv", text)).exit_code == 0
    for unit, z_top in ((2, -45), (3, -80)):
        execute(run.url, "INSERT INTO gear_unit (gear_id, unit, teeth, face_width, z_top) VALUES (%s, %s, 20, 15, %s)",
                (GEAR_ID, unit, z_top))
    jobs = execute(run.url, "SELECT count(*) FROM job")
    result = run("instantiate", "--gear", GEAR_ID)
    assert result.exit_code == 1, result.output
    assert "class duplex cuts two units per set-up (the gear row and unit 2), the gear has 3" in result.stderr
    assert "import its second unit" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert execute(run.url, "SELECT count(*) FROM job") == jobs


# --- work-holdings ----------------------------------------------------------------------

BAD_HOLDINGS = """id,kind,diameter,height,tailstock_diameter,machine
R-OK,arbor,10,60,6,
R-KIND,spindle,10,60,6,
R-NEG,arbor,-4,60,6,
R-NOWHERE,arbor,10,60,6,hobber-9
R-LATHE,arbor,10,60,6,lathe-840d
R-ALSO-NOWHERE,collet,8,50,0,hobber-9
"""


def test_every_bad_work_holding_row_is_named_in_one_run(read_only_run, tmp_path):
    before = read_only_run("fixtures", "list", "--csv").stdout
    result = read_only_run("fixtures", "import", write(tmp_path, "holdings.csv", BAD_HOLDINGS))
    assert result.exit_code == 1
    for words in ("line 3, column kind: 'spindle' is not one of", "line 4, column diameter: -4 must be greater than 0",
                  "line 5, column machine: machine hobber-9 does not exist",
                  "line 6, column machine: machine lathe-840d is a lathe, not a hobber",
                  "line 7, column machine: machine hobber-9 does not exist"):
        assert words in result.stderr, result.stderr
    assert "5 bad row(s)" in result.stderr
    assert read_only_run("fixtures", "list", "--csv").stdout == before


def test_a_centre_wider_than_the_arbor_is_accepted(run, tmp_path):
    """The centre stands above the gear in place of the tailstock, the arbor under it: two parts."""
    path = write(tmp_path, "holdings.csv", "id,kind,diameter,height,tailstock_diameter,machine\nW-D8,arbor,8,60,12,\n")
    result = run("fixtures", "import", path, "--json")
    assert result.exit_code == 0 and json.loads(result.stdout) == {"added": 1, "updated": 0}, result.output


HOB = Hob("H", 2.0, 20.0, 1, 70.0, 100.0, "R", "AA", "HSS", "", "cylindrical", 1, "normal")


def small_gear() -> Gear:
    """m2 z10: d_f = 2·(10 − 2.5) = 15 mm, so at most Ø14 clears it (0.5 mm on the radius)."""
    return Gear(7, "spur", 2.0, 10, 20.0, 0.0, None, 20.0, 24.0, 15.0, None, None, "40Cr", 220.0, 8, 1)


def test_a_holding_of_another_machine_is_refused_in_plain_words(conn):
    machine = load_machine(conn, "hobber-840d")
    library = [WorkHolding("H2-D8", "arbor", 8.0, 80.0, 6.0, "hobber-2")]
    with pytest.raises(EngineError) as refused:
        choose_holding(small_gear(), HOB, machine, library, "H2-D8")
    assert ("arbor H2-D8 does not fit: the job needs a work-holding made for machine hobber-840d or for any "
            "hobber, and H2-D8 is made for machine hobber-2") in str(refused.value)


def test_a_short_holding_is_refused_saying_the_holding_needs_the_height(conn):
    machine = load_machine(conn, "hobber-840d")
    assert machine.fixture_diameter > 14   # the machine's own fixture does not clear the root
    needed = HOB.tip_diameter + HEIGHT_MARGIN - machine.fixture_gap
    library = [WorkHolding("C-SHORT", "collet", 6.0, needed - 5, 0.0)]
    with pytest.raises(EngineError) as refused:
        choose_holding(small_gear(), HOB, machine, library, "C-SHORT")
    said = str(refused.value)
    assert "the gear needs" not in said
    assert f"the job needs a work-holding at least {needed:g} mm high" in said
    assert "out of the hob's reach" in said and f"C-SHORT is {needed - 5:g} mm high" in said


# --- hob gashes -------------------------------------------------------------------------

ADD = ("hobs", "add", "--id", "H-M2-G", "--module", 2, "--tip-diameter", 70, "--length", 100, "--hand", "R",
       "--accuracy-class", "A")


def test_a_hob_with_1000_gashes_is_refused_by_add_and_import(run, tmp_path):
    before = run("hobs", "list", "--csv").stdout
    added = run(*ADD, "--gashes", 1000)
    assert added.exit_code == 1
    assert "write the hob's gashes, 1 to 40" in added.stderr and "from 1 up" not in added.stderr
    assert "gashes 1000 is above 40" in added.stderr and len(added.stderr.strip().splitlines()) == 1, added.stderr
    path = write(tmp_path, "hobs.csv", "id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,"
                                       "gashes\nH-M2-G,2,20,1,70,100,R,A,41\n")
    imported = run("hobs", "import", path)
    assert imported.exit_code == 1 and "line 2, column gashes: 41 is above 40" in imported.stderr, imported.stderr
    assert run("hobs", "list", "--csv").stdout == before
    assert run(*ADD, "--gashes", 40).exit_code == 0


def test_a_unit_for_a_helical_gear_says_no_class_cuts_it(run, tmp_path):
    """Class duplex derives from spur: a helical gear's further toothing has no class that cuts it."""
    text = GEARS.replace(f"{GEAR_ID},,2,30,20,0,,", f"{GEAR_ID},helical,2,30,20,15,R,")
    assert run("gears", "import", write(tmp_path, "gears.csv", text)).exit_code == 0
    added = run("gears", "units", write(tmp_path, "units.csv", UNIT_HEADER + UNIT_2))
    assert added.exit_code == 0, added.output
    assert (f"gear {GEAR_ID}: class helical does not cut further units; class duplex cuts spur units only "
            "(β = 15°): no program cuts these units") in added.stdout
