"""The hob library: choosing a hob for a gear (each property, the reason, the refusal) and
`engine hobs list | add | import | match` against a real PostgreSQL."""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import psycopg
import pytest

from engine.errors import EngineError
from engine.gears.hob_matching import choose_hob
from engine.gears.records import Gear, Hob

SEED_HOBS = Path(__file__).resolve().parent.parent / "seed_templates" / "hobs.csv"

# m 2, α 20°: h = 2.25·2 = 4.5; 2h/tan 20° = 9/0.363970 = 24.727; π·m = 6.283 (§B15).
GENERATING_M2 = 31.010
# Worm-wheel hob m 3, 1 start, da0 50: d_m0 = 50 − 2·1.25·3 = 42.5; γ = asin(3/42.5) = 4.048°.
WORM_HOB_LEAD = 4.048
# Its axial module m_n0/cos γ (§B10): a wheel of helix β fits its pitch with normal module m_x·cos β.
WORM_HOB_AXIAL = 3.0 / math.sqrt(1 - (3.0 / 42.5) ** 2)


def wheel_module(helix: float) -> float:
    """The normal module of a wheel of this helix whose transverse pitch is the hob's axial pitch."""
    return WORM_HOB_AXIAL * math.cos(math.radians(helix))


def hob(hob_id, module=2.0, hand="R", accuracy_class="AA", length=100.0, pressure_angle=20.0,
        tip_diameter=70.0, purpose="cylindrical", starts=1):
    return Hob(hob_id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class,
               "HSS", "TiN", purpose)


def gear(module=2.0, grade=7, hand=None, helix=0.0, pressure_angle=20.0, gear_id=901):
    return Gear(gear_id, "spur" if hand is None else "helical", module, 30, pressure_angle, helix, hand,
                20.0, None, None, None, None, "40Cr", 220.0, grade, 10)


LIBRARY = [
    hob("H-M2-AA-R1"),
    hob("H-M2-A-L1", hand="L", accuracy_class="A"),
    hob("H-M2-AA-R1-PA25", pressure_angle=25.0),
    hob("H-M3-B-R1", module=3.0, accuracy_class="B", tip_diameter=80.0, length=120.0),
    hob("H-WW-M3-R1", module=3.0, accuracy_class="A", tip_diameter=50.0, length=90.0, purpose="worm_wheel"),
]


def refusal(gear_, library=LIBRARY, **options) -> str:
    with pytest.raises(EngineError) as caught:
        choose_hob(gear_, library, **options)
    return str(caught.value)


# --- choosing: one refusal per property ---------------------------------------------------

@pytest.mark.parametrize("gear_, options, first_missing, needed, closest", [
    (gear(module=5.0), {}, "module", "module 5", "module 3 (H-M3-B-R1), module 2"),
    (gear(pressure_angle=14.5), {}, "pressure angle", "pressure angle 14.5°", "pressure angle 20°"),
    (gear(module=3.0, grade=7), {}, "accuracy class", "class AA or better (grade 7)", "class B (H-M3-B-R1)"),
    # needed 31.010 + 60 + 2·5 = 101.0 > 100
    (gear(grade=7), {"shift_travel": 60}, "length", "length ≥ 101.0 mm", "length 100 (H-M2-AA-R1)"),
    (gear(module=3.0, hand="L", helix=WORM_HOB_LEAD, grade=8), {"purpose": "worm_wheel"}, "hand", "hand L",
     "hand R (H-WW-M3-R1)"),
    (gear(module=wheel_module(5.0), hand="R", helix=5.0, grade=8), {"purpose": "worm_wheel"}, "lead angle",
     "lead angle 5° ± 0.5°", "lead angle 4.05° (H-WW-M3-R1)"),
    # a worm wheel is held by axial module m_n/cos β (§B10): 2/cos 4° = 2.004878; the hob's 3/cos 4.048°
    (gear(module=2.0, hand="R", helix=4.0, grade=8), {"purpose": "worm_wheel"}, "module", "axial module 2.00488",
     "axial module 3.0075 (normal 3) (H-WW-M3-R1)"),
])
def test_a_refusal_names_the_gear_the_first_missing_property_and_the_closest_hobs(
        gear_, options, first_missing, needed, closest):
    with pytest.raises(EngineError) as caught:
        choose_hob(gear_, LIBRARY, **options)
    message = str(caught.value)
    assert caught.value.property_name == first_missing
    assert message.startswith(f"gear 901: no hob has {needed}")
    assert closest in message
    assert "engine hobs add" in message and "engine hobs import" in message
    assert "\n" not in message


def test_the_purpose_comes_first_a_worm_wheel_hob_never_cuts_a_cylindrical_gear():
    only_worm_hobs = [h for h in LIBRARY if h.purpose == "worm_wheel"]
    message = refusal(gear(module=3.0, grade=8), only_worm_hobs)
    assert message.startswith("gear 901: no hob has purpose cylindrical: the library has purpose worm_wheel")


def test_an_empty_library_is_said_so():
    assert "the hob library is empty" in refusal(gear(), [])


def test_the_earlier_properties_are_named_with_the_refusal():
    message = refusal(gear(module=3.0, grade=7))
    assert "among those with purpose cylindrical, module 3, pressure angle 20°" in message


# --- choosing: preferences and the reason -------------------------------------------------

@pytest.mark.parametrize("hand, expected", [("L", "H-M2-A-L1"), ("R", "H-M2-AA-R1"), (None, "H-M2-AA-R1")])
def test_a_cylindrical_gear_prefers_a_hob_of_its_own_hand(hand, expected):
    # grade 8 needs class A: both m2 20° hobs qualify, so only the hand decides.
    assert choose_hob(gear(hand=hand, helix=15.0 if hand else 0.0, grade=8), LIBRARY).hob.id == expected


def test_a_cylindrical_gear_takes_the_other_hand_when_its_own_does_not_fit():
    # grade 7 needs AA: the only left-hand m2 hob is class A.
    choice = choose_hob(gear(hand="L", helix=15.0, grade=7), LIBRARY)
    assert choice.hob.id == "H-M2-AA-R1" and "opposite hand (R" in choice.reason


def test_the_coarsest_sufficient_class_is_kept_for_the_gear():
    library = [hob("H-AA"), hob("H-A", accuracy_class="A"), hob("H-B", accuracy_class="B")]
    assert choose_hob(gear(grade=8), library).hob.id == "H-A"      # grade 8 needs A
    assert choose_hob(gear(grade=7), library).hob.id == "H-AA"     # grade 7 needs AA
    assert choose_hob(gear(grade=9), library).hob.id == "H-B"      # grade 9 needs B


@pytest.mark.parametrize("helix, fits", [(WORM_HOB_LEAD, True), (4.5, True), (3.6, True), (4.6, False), (3.5, False)])
def test_a_worm_wheel_needs_the_hob_lead_angle_within_half_a_degree_of_its_helix(helix, fits):
    wheel = gear(module=wheel_module(helix), hand="R", helix=helix, grade=8)
    if fits:
        assert choose_hob(wheel, LIBRARY, purpose="worm_wheel").hob.id == "H-WW-M3-R1"
    else:
        assert "no hob has lead angle" in refusal(wheel, purpose="worm_wheel")


@pytest.mark.parametrize("shift, fits", [(58.9, True), (59.1, False)])
def test_the_hob_must_be_long_enough_for_generating_shift_and_margins(shift, fits):
    # 31.010 + shift + 10 against the hob length 100: the limit is shift 58.99.
    library = [hob("H-M2-AA-R1")]
    if fits:
        assert choose_hob(gear(), library, shift_travel=shift).hob.id == "H-M2-AA-R1"
    else:
        assert "no hob has length" in refusal(gear(), library, shift_travel=shift)


def test_the_reason_names_every_checked_property_with_its_values():
    reason = choose_hob(gear(grade=7), LIBRARY, shift_travel=12).reason
    needed = GENERATING_M2 + 12 + 10
    for words in ("H-M2-AA-R1:", "purpose cylindrical", "module 2", "pressure angle 20°", "class AA",
                  "grade 7 needs AA or better", "hand R", "length 100", f"{needed:.1f} needed",
                  f"generating {GENERATING_M2:.1f}", "shift 12", "margins 10"):
        assert words in reason
    assert "\n" not in reason


def test_the_reason_of_a_worm_wheel_hob_names_hand_and_lead_angle():
    reason = choose_hob(gear(module=3.0, hand="R", helix=4.2, grade=8), LIBRARY, purpose="worm_wheel").reason
    assert "purpose worm_wheel" in reason and "hand R" in reason
    assert f"lead angle {WORM_HOB_LEAD:.2f}°" in reason and "helix 4.2°" in reason


def test_a_wrong_purpose_or_a_negative_shift_is_refused():
    assert "purpose 'bevel'" in refusal(gear(), purpose="bevel")
    assert "shift travel -1" in refusal(gear(), shift_travel=-1)


# --- the command line ---------------------------------------------------------------------



def hob_rows(url) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT * FROM hob ORDER BY id").fetchall()


def execute(url, *statements) -> None:
    with psycopg.connect(url) as conn:
        for statement in statements:
            conn.execute(statement)


def seeded_hob_ids() -> list[str]:
    with SEED_HOBS.open(encoding="utf-8", newline="") as file:
        return [row["id"] for row in csv.DictReader(file)]


def test_list_shows_every_seeded_hob(read_only_run):
    result = read_only_run("hobs", "list")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].split()[:4] == ["id", "module", "kind", "α"]
    assert sorted(line.split()[0] for line in lines[1:]) == sorted(seeded_hob_ids())
    worm = next(line.split() for line in lines if line.startswith("H-WW-M3-R1 "))
    assert worm[1:] == ["3", "normal", "20", "1", "50", "90", "R", "A", "HSS", "TiN", "worm_wheel", "1", "12",
                        "standard"]


def test_add_then_list_shows_the_new_hob(run):
    result = run("hobs", "add", "--id", "H-M5-B-L1", "--module", 5, "--tip-diameter", 110, "--length", 160,
                 "--hand", "l", "--accuracy-class", "b", "--coating", "TiAlN", "--gashes", 14,
                 "--profile", "protuberance")
    assert result.exit_code == 0, result.output
    listed = json.loads(run("hobs", "list", "--json").stdout)["hobs"]
    added = next(h for h in listed if h["hob_id"] == "H-M5-B-L1")
    assert added == {"hob_id": "H-M5-B-L1", "module": 5, "pressure_angle": 20, "starts": 1, "tip_diameter": 110,
                     "length": 160, "hand": "L", "accuracy_class": "B", "material": "HSS",
                     "coating": "TiAlN", "purpose": "cylindrical", "tool_number": 1, "module_kind": "normal",
                     "gashes": 14, "profile": "protuberance"}
    assert len(listed) == len(seeded_hob_ids()) + 1


@pytest.mark.parametrize("options, words", [
    (("--id", "H-M2-AA-R1", "--module", 2, "--tip-diameter", 70, "--length", 100, "--hand", "R",
      "--accuracy-class", "AA"), ["hob H-M2-AA-R1 already exists"]),
    (("--id", "X", "--module", 0, "--tip-diameter", 70, "--length", 100, "--hand", "R",
      "--accuracy-class", "AA"), ["module 0 must be greater than 0"]),
    (("--id", "X", "--module", 2, "--tip-diameter", 9, "--length", -1, "--hand", "S",
      "--accuracy-class", "E", "--purpose", "bevel", "--pressure-angle", 45, "--starts", 0),
     ["tip_diameter 9 is not greater than 2·2.25·module = 9", "length -1 must be greater than 0",
      "hand 'S' must be L or R", "accuracy_class 'E' is not one of", "purpose 'bevel' is not one of",
      "pressure_angle 45 is outside (0, 45)", "starts '0' is not a positive whole number"]),
])
def test_a_bad_or_duplicate_hob_is_refused_and_nothing_changes(read_only_run, options, words):
    before = hob_rows(read_only_run.url)
    result = read_only_run("hobs", "add", *options)
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert message.startswith("error: ") and "\n" not in message
    for word in words:
        assert word in message
    assert hob_rows(read_only_run.url) == before


GOOD_CSV = """id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,material,coating,purpose,\
module_kind
H-M2-AA-R1,2,20,1,70,150,R,AA,HSS,TiAlN,cylindrical,
H-M6-B-R1,6,20,1,125,200,R,B,,,,
H-WW-M4-L1,4,20,2,60,110,L,A,PM-HSS,TiN,worm_wheel,axial
"""


def test_import_adds_new_hobs_and_updates_existing_ones(run, tmp_path):
    path = tmp_path / "hobs.csv"
    path.write_text(GOOD_CSV, encoding="utf-8")
    result = run("hobs", "import", path, "--json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == {"added": 2, "updated": 1, "kept": ["tool_number", "gashes", "profile"]}
    listed = {h["hob_id"]: h for h in json.loads(run("hobs", "list", "--json").stdout)["hobs"]}
    assert len(listed) == len(seeded_hob_ids()) + 2
    assert (listed["H-M2-AA-R1"]["length"], listed["H-M2-AA-R1"]["coating"]) == (150, "TiAlN")
    assert (listed["H-M6-B-R1"]["material"], listed["H-M6-B-R1"]["coating"],
            listed["H-M6-B-R1"]["purpose"]) == ("HSS", "", "cylindrical")
    assert (listed["H-WW-M4-L1"]["starts"], listed["H-WW-M4-L1"]["purpose"]) == (2, "worm_wheel")
    assert (listed["H-WW-M4-L1"]["module"], listed["H-WW-M4-L1"]["module_kind"]) == (4, "axial")   # as catalogued
    again = run("hobs", "import", path)
    assert again.exit_code == 0 and "added 0 hob(s), updated 3" in again.stdout


def test_an_import_without_a_column_keeps_each_updated_hobs_own_value(run, tmp_path):
    """New-user review: a file in the columns of an older seed_templates/hobs.csv (no tool_number,
    gashes, profile) reset a hob set up as T5 to T1: its programs would call the wrong tool."""
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE hob SET tool_number = 5, gashes = 14, profile = 'protuberance' "
                     "WHERE id = 'H-M2-AA-R1'")
    path = tmp_path / "hobs.csv"
    path.write_text(GOOD_CSV, encoding="utf-8")
    result = run("hobs", "import", path)
    assert result.exit_code == 0, result.output
    assert "kept as they were: tool_number, gashes, profile" in result.stdout
    with psycopg.connect(run.url) as conn:
        row = conn.execute("SELECT tool_number, gashes, profile, length, coating FROM hob "
                           "WHERE id = 'H-M2-AA-R1'").fetchone()
        new = conn.execute("SELECT tool_number, gashes, profile FROM hob WHERE id = 'H-M6-B-R1'").fetchone()
    assert row == (5, 14, "protuberance", 150, "TiAlN"), "the columns given are updated, the others kept"
    assert new == (1, 12, "standard"), "a new hob gets the defaults of the columns left out"


@pytest.mark.parametrize("row, words", [
    ("H-WW-X,3,20,1,50,90,R,A,worm_wheel,", "column module_kind: is missing: a worm-wheel hob's record must say"),
    ("H-CYL-X,3,20,1,80,120,R,A,cylindrical,axial", "column module_kind: axial is for worm-wheel hobs"),
    ("H-WW-Y,3,20,1,50,90,R,A,worm_wheel,transverse", "column module_kind: 'transverse' must be normal or axial"),
])
def test_a_hob_whose_module_is_not_said_plainly_is_refused(read_only_run, tmp_path, row, words):
    """A catalogue worm-wheel hob gives its worm's axial module (DIN 3975): read as normal, its
    tangential feed would be coupled to the wrong pitch, so its record must say which it gives."""
    before = hob_rows(read_only_run.url)
    path = tmp_path / "hobs.csv"
    path.write_text("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,purpose,module_kind\n"
                    f"{row}\n", encoding="utf-8")
    result = read_only_run("hobs", "import", path)
    assert result.exit_code == 1 and words in result.stderr, result.output
    assert hob_rows(read_only_run.url) == before


def test_import_without_the_optional_columns(run, tmp_path):
    path = tmp_path / "hobs.csv"
    path.write_text("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class\n"
                    "H-M7-C-R1,7,20,1,140,220,R,C\n", encoding="utf-8")
    assert json.loads(run("hobs", "import", path, "--json").stdout) == {"added": 1, "updated": 0, "kept": []}


BAD_CSV = """id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,purpose
H-OK-1,2,20,1,70,100,R,AA,cylindrical

H-BAD-MODULE,two,20,1,70,100,R,AA,cylindrical
H-OK-2,2,20,1,70,100,R,AA,cylindrical
H-BAD-MANY,2,20,1.5,8,100,X,AA,bevel
H-OK-1,2,20,1,70,100,R,AA,cylindrical
,2,20,1,70,100,R,AA,
"""


def test_a_bad_import_reports_every_bad_line_and_stores_nothing(read_only_run, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text(BAD_CSV, encoding="utf-8")
    before = hob_rows(read_only_run.url)
    result = read_only_run("hobs", "import", path)
    assert result.exit_code == 1, result.output
    lines = result.stderr.splitlines()
    assert lines[0] == f"error: {path}: 4 bad row(s); nothing imported"
    problems = [line.strip() for line in lines[1:]]
    # physical lines: header 1, H-OK-1 2, blank 3, H-BAD-MODULE 4, H-OK-2 5, H-BAD-MANY 6, ...
    assert problems == [f"{path}, {problem}" for problem in (
        "line 4, column module: 'two' is not a number; write a number in mm like 2.5",
        "line 6, column starts: '1.5' is not a positive whole number; write a whole number from 1 up",
        "line 6, column hand: 'X' must be L or R; write L or R (the helix hand)",
        "line 6, column purpose: 'bevel' is not one of cylindrical, worm_wheel; write one of cylindrical, worm_wheel",
        "line 6, column tip_diameter: 8 is not greater than 2·2.25·module = 9 (two tooth depths); check the module "
        "and the tip diameter",
        "line 7, column id: H-OK-1 is already on line 2; give each hob once",
        "line 8, column id: is missing; write an id like H-M2-AA-R1",
    )]
    assert hob_rows(read_only_run.url) == before


def test_an_import_with_an_unknown_column_is_refused(read_only_run, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("id,module,diameter\nX,2,70\n", encoding="utf-8")
    result = read_only_run("hobs", "import", path)
    assert result.exit_code == 1
    assert "line 1: unknown column(s) diameter" in result.stderr and "missing required column(s)" in result.stderr


HEADER = "id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class\n"


@pytest.mark.parametrize("rows, words", [
    ("h-m2-aa-r1,2,20,1,70,150,R,AA\n", "hob h-m2-aa-r1 is hob H-M2-AA-R1 of the library"),
    ("H-M9-A-R1,9,20,1,170,200,R,A\nh-m9-a-r1,9,20,1,170,200,R,A\n",
     "line 3, column id: h-m9-a-r1 is already on line 2"),
])
def test_an_import_of_a_hob_id_differing_only_in_case_is_refused(read_only_run, tmp_path, rows, words):
    path = tmp_path / "hobs.csv"
    path.write_text(HEADER + rows, encoding="utf-8")
    before = hob_rows(read_only_run.url)
    result = read_only_run("hobs", "import", path)
    assert result.exit_code == 1, result.output
    assert words in result.stderr and "ids that differ only in case name one hob" in result.stderr
    assert hob_rows(read_only_run.url) == before


def test_an_added_hob_id_differing_only_in_case_is_refused_and_so_is_it_in_sql(run):
    before = hob_rows(run.url)
    result = run("hobs", "add", "--id", "h-m2-aa-r1", "--module", 2, "--tip-diameter", 70, "--length", 100,
                 "--hand", "R", "--accuracy-class", "AA")
    assert result.exit_code == 1 and "hob h-m2-aa-r1 is hob H-M2-AA-R1 of the library" in result.stderr
    with pytest.raises(psycopg.errors.UniqueViolation, match="hob_id_ignoring_case"):
        execute(run.url, "INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class) "
                         "VALUES ('h-m2-aa-r1', 2, 1, 70, 100, 'R', 'AA')")
    assert hob_rows(run.url) == before


def test_match_names_the_hob_of_the_seeded_gear_42(read_only_run):
    # gear 42: m 2, α 20°, grade 7 (needs AA), spur → H-M2-AA-R1 (the paper's 1-start AA hob).
    result = read_only_run("hobs", "match", "--gear", 42)
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[0] == "gear 42: hob H-M2-AA-R1"
    assert "class AA (grade 7 needs AA or better)" in result.stdout
    shifted = json.loads(read_only_run("hobs", "match", "--gear", 42, "--shift-travel", 20, "--json").stdout)
    assert shifted["hob_id"] == "H-M2-AA-R1" and f"{GENERATING_M2 + 30:.1f} needed" in shifted["reason"]


def test_match_says_which_property_no_hob_has(run):
    # m 4 grade 6 needs class AA; the only m4 hob is class A.
    execute(run.url, "INSERT INTO gear (id, gear_class, module, teeth, face_width, quality_grade) "
                     "VALUES (9001, 'spur', 4, 30, 40, 6)")
    before = hob_rows(run.url)
    result = run("hobs", "match", "--gear", 9001)
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert message.startswith("error: gear 9001: no hob has class AA or better (grade 6)")
    assert "module 4" in message and "class A (H-M4-A-R1)" in message
    assert hob_rows(run.url) == before


def test_match_takes_a_worm_wheel_hob_for_a_worm_wheel_class(run):
    execute(run.url,
            "INSERT INTO gear_class (name, parent) VALUES ('worm_wheel_radial', 'worm_wheel')",
            "INSERT INTO gear (id, gear_class, module, teeth, helix_angle, hand, face_width, quality_grade) "
            "VALUES (9002, 'worm_wheel_radial', 3, 40, 4.05, 'R', 30, 8)")
    result = run("hobs", "match", "--gear", 9002)
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[0] == "gear 9002: hob H-WW-M3-R1"
    assert "purpose worm_wheel" in result.stdout and "lead angle 4.05°" in result.stdout
    # Asked for a cylindrical hob, the same gear gets the right-hand m3 one (grade 8 needs A).
    cylindrical = run("hobs", "match", "--gear", 9002, "--purpose", "cylindrical")
    assert cylindrical.stdout.splitlines()[0] == "gear 9002: hob H-M3-AA-R1"


def test_match_of_a_missing_gear_is_refused(read_only_run):
    result = read_only_run("hobs", "match", "--gear", 999)
    assert result.exit_code == 1 and "gear 999 does not exist" in result.stderr


def test_the_list_as_csv_is_a_file_import_reads_back_unchanged(run, tmp_path):
    """sqlite-utils' rule: every list exports what its import reads (adversary and new-user review 29:
    the header said hob_id, the import wants id)."""
    listed = run("hobs", "list", "--csv")
    assert listed.exit_code == 0 and listed.stdout.splitlines()[0].startswith("id,module,module_kind,")
    path = tmp_path / "hobs.csv"
    path.write_text(listed.stdout, encoding="utf-8")
    before = hob_rows(run.url)
    again = run("hobs", "import", path, "--json")
    assert again.exit_code == 0, again.output
    assert json.loads(again.stdout) == {"added": 0, "updated": len(before), "kept": []}
    assert hob_rows(run.url) == before
