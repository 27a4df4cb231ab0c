"""Work-holding per job (issue 29): a small gear whose root the machine's own fixture does not
clear is clamped on the largest arbor of the library that does, its program states it and the
simulation proves it against the arbor's solids; a too-large one given with --fixture, a program
whose hob enters the arbor or that misstates its work-holding, and bad CSV rows are refused.
Expected sizes come from the gear, hob, machine and seed records, computed here."""
from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import psycopg
import pytest

from engine.errors import EngineError
from engine.gears.holding_matching import choose_holding
from engine.gears.records import Gear, Hob, load_gear, load_hobs
from engine.machines.records import load_machine
from engine.machines.work_holding import WorkHolding, job_work_holding, jobs_work_holdings, load_work_holding
from engine.simulation import simulate_program

SEED_HOLDINGS = Path(__file__).resolve().parent.parent / "seed_templates" / "work_holdings.csv"
MACHINE = "hobber-840d"
# m 1.25 z 14 spur: d_f = m·(z − 2·1.25) = 14.375 mm, under the seeded hobber's Ø20 fixture.
MODULE, TEETH, FACE = 1.25, 14, 12.0
GEAR_CSV = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,tip_diameter,root_diameter,"
            "cone_angle,crowning,material,hardness,quality_grade,quantity,module_kind\n"
            f"901,spur,{MODULE},{TEETH},20,0,,{FACE:g},,,,,40Cr,250,8,10,\n")
HOB_TIP, HOB_ID = 50.0, "H-M1.25-A-R1"
HOB_CSV = ("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,material,coating,purpose,"
           f"module_kind\n{HOB_ID},{MODULE},20,1,{HOB_TIP:g},60,R,A,HSS,TiN,cylindrical,normal\n")
SETTER_CLEARANCE = 0.5   # mm on the radius the part under the gear keeps inside the root (the setter's rule)
HOB_RUN_IN = 5.0         # mm beyond the hob's tip diameter the machine's fixture must stand below the gear


def root_diameter() -> float:
    return MODULE * (TEETH - 2 * 1.25)


def seeded_holdings() -> list[dict]:
    with SEED_HOLDINGS.open(encoding="utf-8") as file:
        return list(csv.DictReader(file))


def expected_arbor(machine_fixture: float, machine_gap: float) -> dict:
    """The setter's choice from the seed file: fits the machine, clears the root below and above by
    the clearance, stands the machine's fixture a hob diameter (and run-in) below the gear; the largest."""
    largest = root_diameter() - 2 * SETTER_CLEARANCE
    height = HOB_TIP + HOB_RUN_IN - machine_gap if machine_fixture > largest else 0.0
    fitting = [row for row in seeded_holdings() if row["machine"] in ("", MACHINE)
               and float(row["diameter"]) <= largest and float(row["tailstock_diameter"] or 0) <= largest
               and float(row["height"]) >= height]
    return max(fitting, key=lambda row: (float(row["diameter"]), float(row["tailstock_diameter"] or 0)))


@pytest.fixture
def small_gear(run, tmp_path):
    """Gear 901 (m 1.25 z 14) and an m 1.25 hob in the private database of `run`."""
    (tmp_path / "gear.csv").write_text(GEAR_CSV, encoding="utf-8")
    (tmp_path / "hob.csv").write_text(HOB_CSV, encoding="utf-8")
    assert run("gears", "import", tmp_path / "gear.csv").exit_code == 0
    assert run("hobs", "import", tmp_path / "hob.csv").exit_code == 0
    return run


def stored(url: str, program_id: int) -> tuple[list[str], str | None]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT p.lines, j.work_holding_id FROM program p JOIN job j ON j.id = p.job_id "
                            "WHERE p.id = %s", (program_id,)).fetchone()


def records(url: str):
    with psycopg.connect(url) as conn:
        hob = next(hob for hob in load_hobs(conn) if hob.id == HOB_ID)
        return load_gear(conn, 901), hob, load_machine(conn, MACHINE), conn.execute(
            "SELECT count(*) FROM job").fetchone()[0]


def test_the_small_gear_is_refused_on_the_machines_own_fixture(small_gear):
    """Before issue 29 the hobber's Ø20 fixture stood under every gear: the hob at the root enters it."""
    with psycopg.connect(small_gear.url) as conn:
        conn.execute("DELETE FROM work_holding")
    machine = records(small_gear.url)[2]
    assert machine.fixture_diameter > root_diameter()
    result = small_gear("instantiate", "--gear", 901)
    assert result.exit_code == 1 and re.search(r"runs [0-9.]+ mm into the (fixture|tailstock)", result.stderr), \
        result.output


def test_the_small_gear_is_made_on_the_largest_arbor_that_fits_and_proved(small_gear):
    gear, hob, machine, _ = records(small_gear.url)
    wanted = expected_arbor(machine.fixture_diameter, machine.fixture_gap)
    match = small_gear("fixtures", "match", "--gear", 901, "--json")
    assert match.exit_code == 0 and json.loads(match.stdout)["fixture_id"] == wanted["id"], match.output
    result = small_gear("instantiate", "--gear", 901, "--json")
    assert result.exit_code == 0, result.output
    program_id = json.loads(result.stdout)["program_id"]
    lines, holding_id = stored(small_gear.url, program_id)
    assert holding_id == wanted["id"]
    assert lines.count(f"; FIXTURE {wanted['id']}") == 1
    assert lines.index(f"; FIXTURE {wanted['id']}") < next(i for i, line in enumerate(lines) if line.startswith("G0"))
    assert small_gear("simulate", "--program", program_id).exit_code == 0
    job_id = json.loads(result.stdout)["job_id"]
    again = small_gear("instantiate", "--job", job_id, "--json")   # a stored job keeps and proves its arbor
    assert again.exit_code == 0, again.output


def test_the_work_holdings_of_many_jobs_read_at_once_are_each_jobs_own(small_gear):
    """The release impact reads the work-holdings of thousands of jobs in one go (issue 28): each job's
    is the one it is clamped on, as read job by job; a job on the machine's own fixture, or no job, None."""
    machine = records(small_gear.url)[2]
    on_arbor = json.loads(small_gear("instantiate", "--gear", 901, "--json").stdout)["job_id"]
    on_fixture = json.loads(small_gear("instantiate", "--gear", 42, "--json").stdout)["job_id"]
    with psycopg.connect(small_gear.url) as conn:
        held = jobs_work_holdings(conn, [on_arbor, on_fixture, on_arbor + on_fixture + 1])
        assert held == {on_arbor: job_work_holding(conn, on_arbor), on_fixture: None, on_arbor + on_fixture + 1: None}
    assert held[on_arbor].id == expected_arbor(machine.fixture_diameter, machine.fixture_gap)["id"]


def test_a_hob_path_into_the_arbor_is_refused(small_gear):
    """Below the gear (the hob's tip circle clear of the bottom face), a G1 toward the axis until the
    hob's tip is half a millimetre inside the arbor's radius: the simulation names the arbor."""
    result = small_gear("instantiate", "--gear", 901, "--json")
    lines, holding_id = stored(small_gear.url, json.loads(result.stdout)["program_id"])
    gear, hob, machine, _ = records(small_gear.url)
    with psycopg.connect(small_gear.url) as conn:
        holding = load_work_holding(conn, holding_id)
    r0 = hob.tip_diameter / 2
    below = -(gear.face_width + r0 + 3.0)            # hob centre Z: its tip circle 3 mm under the bottom face
    into = holding.diameter / 2 + r0 - 0.5           # hob centre X: its tip 0.5 mm inside the arbor
    assert below - r0 > -(gear.face_width + machine.fixture_gap + holding.height)   # above the machine's fixture
    edited = _edited(lines, below, into)
    report = simulate_program(edited, gear, hob, machine, "EDITED", holding)
    assert report.refused
    refusals = [finding for finding in report.findings if finding.refuses]
    assert any(f"the {holding.kind} {holding.id}" in finding.message for finding in refusals), report.lines()
    assert not simulate_program(lines, gear, hob, machine, "STORED", holding).refused


def _edited(lines: list[str], below: float, into: float) -> list[str]:
    """The stored program with its working area opened down to `below` − 5 and, after the pass,
    a feed down to Z`below` and in to X`into` (still coupled, the hob turning)."""
    edited = []
    for line in lines:
        if line.startswith("G25 "):
            words = line.split()
            line = " ".join(words[:-1] + [f"Z{below - 5:.3f}"])
        edited.append(line)
        if line.startswith("G1 Z"):
            edited += [f"G1 Z{below:.3f}", f"G1 X{into:.3f}"]
    return edited


@pytest.mark.parametrize("change, words", [
    (lambda lines, fid: [line for line in lines if line != f"; FIXTURE {fid}"], "does not state its work-holding"),
    (lambda lines, fid: [line.replace(fid, "A-D8-H60") for line in lines], "names work-holding A-D8-H60"),
])
def test_a_program_misstating_its_work_holding_is_refused(small_gear, change, words):
    result = small_gear("instantiate", "--gear", 901, "--json")
    lines, holding_id = stored(small_gear.url, json.loads(result.stdout)["program_id"])
    gear, hob, machine, _ = records(small_gear.url)
    with psycopg.connect(small_gear.url) as conn:
        holding = load_work_holding(conn, holding_id)
    report = simulate_program(change(lines, holding_id), gear, hob, machine, "EDITED", holding)
    assert report.refused and any(words in finding.message for finding in report.findings), report.lines()


def test_a_fixture_line_without_a_work_holding_is_refused(run):
    """Gear 42 on the machine's own fixture: a `; FIXTURE` line claims a clamping nobody proved."""
    result = run("instantiate", "--gear", 42, "--json")
    assert result.exit_code == 0, result.output
    lines, holding_id = stored(run.url, json.loads(result.stdout)["program_id"])
    assert holding_id is None and not any(line.startswith("; FIXTURE") for line in lines)
    with psycopg.connect(run.url) as conn:
        gear, machine = load_gear(conn, 42), load_machine(conn, MACHINE)
        hob = next(hob for hob in load_hobs(conn) if f"; HOB {hob.id} " in "\n".join(lines))
    at = lines.index(f"; MACHINE {MACHINE}") + 1
    report = simulate_program(lines[:at] + ["; FIXTURE A-D12-H60"] + lines[at:], gear, hob, machine, "EDITED")
    assert report.refused and any("names no work-holding" in finding.message for finding in report.findings)


def test_a_fixture_too_large_for_the_root_is_refused_naming_it(small_gear):
    largest = root_diameter() - 2 * SETTER_CLEARANCE
    too_large = min((row for row in seeded_holdings() if float(row["diameter"]) > largest),
                    key=lambda row: float(row["diameter"]))
    jobs = records(small_gear.url)[3]
    result = small_gear("instantiate", "--gear", 901, "--fixture", too_large["id"])
    assert result.exit_code == 1, result.output
    assert too_large["id"] in result.stderr and f"Ø{float(too_large['diameter']):g}" in result.stderr
    assert f"at most Ø{largest:g}" in result.stderr
    assert "tried" not in result.stderr, "no hob or feed mode makes it fit: refused at once, not after the search"
    assert records(small_gear.url)[3] == jobs   # nothing stored


def test_a_fixture_given_that_fits_is_used(small_gear):
    smallest = min(seeded_holdings(), key=lambda row: float(row["diameter"]))
    result = small_gear("instantiate", "--gear", 901, "--fixture", smallest["id"], "--json")
    assert result.exit_code == 0, result.output
    assert stored(small_gear.url, json.loads(result.stdout)["program_id"])[1] == smallest["id"]


def gear_record(root: float) -> Gear:
    module = 2.0
    teeth = round(root / module + 2.5)
    return Gear(7, "spur", module, teeth, 20.0, 0.0, None, 20.0, module * (teeth + 2), module * (teeth - 2.5),
                None, None, "40Cr", 220.0, 8, 1)


HOB = Hob("H", 2.0, 20.0, 1, 70.0, 100.0, "R", "AA", "HSS", "", "cylindrical", 1, "normal")


def test_the_machines_own_fixture_stands_when_it_clears_the_root(conn):
    machine = load_machine(conn, MACHINE)
    gear = gear_record(40.0)
    assert gear.root_diameter - 2 * SETTER_CLEARANCE >= max(machine.fixture_diameter, machine.tailstock_diameter)
    choice = choose_holding(gear, HOB, machine, [WorkHolding("A", "arbor", 30.0, 80.0, 10.0)])
    assert choice.holding is None and "the machine's own" in choice.reason


def test_a_holding_of_another_machine_or_with_a_large_centre_is_not_chosen(conn):
    machine = load_machine(conn, MACHINE)
    gear = gear_record(16.0)   # d_f 15 mm: at most Ø14 under and over it
    library = [WorkHolding("OTHER", "arbor", 13.0, 80.0, 8.0, "lathe-840d"),
               WorkHolding("BIG-CENTRE", "arbor", 13.5, 80.0, 14.5),
               WorkHolding("SHORT", "arbor", 13.8, HOB.tip_diameter + HOB_RUN_IN - 1, 8.0),
               WorkHolding("GOOD", "collet", 12.0, HOB.tip_diameter + HOB_RUN_IN, 0.0)]
    choice = choose_holding(gear, HOB, machine, library)
    assert choice.holding is not None and choice.holding.id == "GOOD", choice.reason
    with pytest.raises(EngineError, match="SHORT is [0-9.]+ mm high"):
        choose_holding(gear, HOB, machine, library, "SHORT")


BAD_CSV = """id,kind,diameter,height,tailstock_diameter,machine
A-OK,arbor,10,60,6,
B-KIND,spindle,10,60,6,
C-NEG,arbor,-4,60,6,
D-NOHEIGHT,arbor,10,,6,
A-OK,collet,8,50,0,
"""


def test_a_bad_import_names_every_bad_line_and_stores_nothing(read_only_run, tmp_path):
    path = tmp_path / "holdings.csv"
    path.write_text(BAD_CSV, encoding="utf-8")
    before = read_only_run("fixtures", "list", "--csv").stdout
    result = read_only_run("fixtures", "import", path)
    assert result.exit_code == 1
    for words in ("line 3, column kind: 'spindle' is not one of arbor, mandrel, collet, centres",
                  "line 4, column diameter: -4 must be greater than 0", "line 5, column height: is missing",
                  "line 6, column id: A-OK is already on line 2"):
        assert words in result.stderr, result.stderr
    assert read_only_run("fixtures", "list", "--csv").stdout == before


def test_an_import_naming_an_unknown_machine_stores_nothing(read_only_run, tmp_path):
    path = tmp_path / "holdings.csv"
    path.write_text("id,kind,diameter,height,tailstock_diameter,machine\nX-1,arbor,10,60,6,nowhere\n",
                    encoding="utf-8")
    result = read_only_run("fixtures", "import", path)
    assert result.exit_code == 1 and "machine nowhere does not exist" in result.stderr


def test_the_listed_csv_imports_again_unchanged(run, tmp_path):
    listed = run("fixtures", "list", "--csv")
    assert listed.exit_code == 0
    assert len(listed.stdout.splitlines()) == len(seeded_holdings()) + 1
    path = tmp_path / "again.csv"
    path.write_text(listed.stdout, encoding="utf-8")
    result = run("fixtures", "import", path, "--json")
    assert result.exit_code == 0 and json.loads(result.stdout) == {"added": 0, "updated": len(seeded_holdings())}
    assert run("fixtures", "list", "--csv").stdout == listed.stdout
    rows = {row["id"]: row for row in csv.DictReader(listed.stdout.splitlines())}
    for seeded in seeded_holdings():
        assert {key: rows[seeded["id"]][key] for key in seeded} == seeded
