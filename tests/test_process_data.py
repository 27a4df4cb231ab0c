"""Process data of a hobbing job (issue 14, "Quality and tool life"): the worm wheel's module
stated as axial or normal, worm wheels never guessed by the classification, the hunting-tooth
warning, and the process allowance. Expected numbers come from the reference (§B3, §B10,
§B14), not from the engine."""
from __future__ import annotations

import json
import math

import pytest

from engine.errors import EngineError
from engine.gears.classify import classify
from engine.gears.gear_import import GearImportError
from engine.gears.gear_store import import_gears
from engine.gears.records import load_gear
from engine.hobbing.choices import Choices
from engine.paths import SEED_DIR
from engine.programs.instantiate import instantiate_gear

HEADER = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,tip_diameter,root_diameter,"
          "cone_angle,crowning,material,hardness,quality_grade,quantity,module_kind")
# A worm wheel as its drawing gives it: the worm's axial module 3, 40 teeth, lead angle 4.05° right hand.
MX, Z2, GAMMA, HOB_TIP = 3.0, 40, 4.05, 50.0
MN = MX * math.cos(math.radians(GAMMA))          # §B10: the wheel's normal module m_n = m_x·cos γ


def write(tmp_path, *rows: str):
    path = tmp_path / "gears.csv"
    path.write_text("\n".join([HEADER, *rows]) + "\n")
    return path


def import_refused(conn, path) -> list[str]:
    with pytest.raises(GearImportError) as caught:
        import_gears(conn, path)
    return caught.value.problems


def add_worm_hob(conn, module: float, hob_id: str = "H-WW-MX3-R1") -> None:
    """A worm-wheel hob copying the worm of normal module `module` (the library's modules are normal)."""
    conn.execute("INSERT INTO hob (id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class, "
                 "material, coating, purpose) VALUES (%s, %s, 20, 1, %s, 90, 'R', 'A', 'HSS', 'TiN', 'worm_wheel')",
                 (hob_id, repr(module), HOB_TIP))
    conn.execute("UPDATE hob SET purpose = 'cylindrical' WHERE id = 'H-WW-M3-R1'")   # only the worm's own copy fits


def final_cut_x(conn, program) -> float:
    params = conn.execute("SELECT module_params FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    return params["cutmotion:2"]["cut_x"]


# --- the module of a worm wheel: axial or normal, never guessed -------------------------

def test_a_worm_wheel_stated_in_the_axial_module_is_cut_to_the_depth_of_its_normal_module(conn, tmp_path):
    add_worm_hob(conn, MN)
    import_gears(conn, write(tmp_path, f"90101,worm_wheel,{MX},{Z2},20,{GAMMA},R,25,,,,,CuSn12,90,8,1,axial"))
    gear = load_gear(conn, 90101)
    assert gear.module == pytest.approx(MN, abs=1e-9) and gear.stated_module == pytest.approx(MX)
    # d2 = m_x·z2 (= m_n·z2/cos γ); tip d2 + 2·m_n, root tip − 2·2.25·m_n; full depth a = (d_f2 + d_a0)/2 (§B3)
    tip = MX * Z2 + 2 * MN
    root = tip - 4.5 * MN
    assert float(gear.tip_diameter) == pytest.approx(tip, abs=1e-6)
    assert float(gear.root_diameter) == pytest.approx(root, abs=1e-6)
    program = instantiate_gear(conn, 90101)
    assert final_cut_x(conn, program) == pytest.approx((root + HOB_TIP) / 2, abs=0.001)
    # Read as a normal module the same drawing gives d = 3·40/cos γ: the cut would stay ~0.15 mm shallow.
    root_as_normal = MX * Z2 / math.cos(math.radians(GAMMA)) + 2 * MX - 4.5 * MX
    assert 0.13 < (root_as_normal - root) / 2 < 0.16


def test_the_hob_must_copy_the_worm_of_the_converted_module(conn, tmp_path):
    """The seeded worm hob has normal module 3 (a worm of m_x 3.0075): it is not the copy of an m_x 3 worm."""
    import_gears(conn, write(tmp_path, f"90102,worm_wheel,{MX},{Z2},20,{GAMMA},R,25,,,,,CuSn12,90,8,1,axial"))
    with pytest.raises(EngineError, match=r"gear 90102: no hob has axial module 3 among"):
        instantiate_gear(conn, 90102)


@pytest.mark.parametrize("row, problem", [
    (f"90103,worm_wheel,3,40,20,{GAMMA},R,25,,,,,CuSn12,90,8,1,", "is missing; a worm wheel needs axial"),
    ("90103,spur,3,40,20,0,,25,,,,,45,200,8,1,axial", "axial is for worm wheels"),
    ("90103,spur,3,40,20,0,,25,,,,,45,200,8,1,transverse", "'transverse' must be normal or axial"),
])
def test_the_module_kind_of_a_worm_wheel_is_required_and_axial_is_only_for_worm_wheels(conn, tmp_path, row, problem):
    problems = import_refused(conn, write(tmp_path, row))
    assert len(problems) == 1 and ", line 2, column module_kind: " in problems[0] and problem in problems[0]


def test_a_cylindrical_gear_without_a_module_kind_is_stored_as_normal(conn, tmp_path):
    import_gears(conn, write(tmp_path, "90104,spur,2,30,20,0,,20,,,,,45,200,8,1,"))
    row = conn.execute("SELECT module_kind, tip_diameter FROM gear WHERE id = 90104").fetchone()
    assert row[0] == "normal" and float(row[1]) == 2 * 30 + 2 * 2


def test_a_worm_wheel_whose_module_kind_is_not_stated_is_refused(conn):
    conn.execute("UPDATE gear SET module_kind = NULL WHERE id = 53")
    with pytest.raises(EngineError, match="gear 53: worm wheel module 3 is not stated as axial or normal"):
        instantiate_gear(conn, 53)


def test_the_seeded_worm_wheel_53_is_stated_in_its_normal_module_as_its_helix_shows():
    """Gear 53's helix 4.05° is its hob's (and worm's) lead angle with m_n = 3: sin γ = z0·m_n/d_m0, d_m0 =
    50 − 2.5·3 (§B1) gives 4.048°; an axial module 3 would give tan γ = 3/42.5, 4.038°, and need a hob of
    normal module 2.9925, which the library does not hold. So the seed states module_kind normal."""
    rows = [line.split(",") for line in (SEED_DIR / "gears.csv").read_text().splitlines()]
    seeded = dict(zip(rows[0], next(row for row in rows if row[0] == "53")))
    assert seeded["module_kind"] == "normal"
    normal_reading = math.degrees(math.asin(3 / (HOB_TIP - 2.5 * 3)))
    axial_reading = math.degrees(math.atan(3 / (HOB_TIP - 2.5 * 3)))
    assert round(normal_reading, 2) == float(seeded["helix_angle"]) != round(axial_reading, 2)


# --- classification does not guess worm wheels ------------------------------------------

@pytest.mark.parametrize("gear", [
    {"gear_id": 7, "helix_angle": 4.05, "material": "CuSn12"},
    {"gear_id": 7, "helix_angle": 5.7, "material": "45"},
    {"gear_id": 7, "helix_angle": 15, "material": "G-CuAl10Ni"},
])
def test_a_gear_that_looks_like_a_worm_wheel_gets_no_class_but_a_request(gear):
    found = classify(gear)
    assert found.gear_class is None and "worm wheel" in found.problem
    assert found.remedy == "give gear_class worm_wheel (or helical) explicitly"


@pytest.mark.parametrize("gear, expected", [
    ({"helix_angle": 15, "material": "20CrMnTi"}, "helical"),
    ({"helix_angle": 8, "material": "45"}, "helical"),
    ({"helix_angle": 0, "material": "CuSn12"}, "spur"),
    ({"helix_angle": 5, "cone_angle": 3, "material": "45"}, "taper"),
])
def test_steel_helical_and_other_gears_are_classified_as_before(gear, expected):
    assert classify(gear).gear_class == expected


def test_an_import_of_a_worm_wheel_without_a_class_is_refused_in_one_line_naming_the_gear(conn, tmp_path):
    problems = import_refused(conn, write(tmp_path, f"90105,,3,40,20,{GAMMA},R,25,,,,,CuSn12,90,8,1,axial"))
    assert len(problems) == 1
    assert ", line 2, column gear_class: gear 90105 looks like a worm wheel" in problems[0]
    assert problems[0].endswith("give gear_class worm_wheel (or helical) explicitly")


def test_the_seeded_gears_without_a_class_keep_theirs(conn):
    classes = dict(conn.execute("SELECT id, gear_class FROM gear WHERE id IN (50, 51)").fetchall())
    assert classes == {50: "taper", 51: "crowned"}


# --- hunting tooth ----------------------------------------------------------------------

def test_hob_starts_sharing_a_factor_with_the_teeth_warn_once_per_job(conn):
    """Seeded gear 46: z2 = 48 and the 2-start hob H-M1.5-A-R2, gcd(2, 48) = 2."""
    program = instantiate_gear(conn, 46)
    hunting = [note for note in program.notes if "hunting" in note]
    assert len(hunting) == 1 and "gear 46" in hunting[0] and "common factor 2" in hunting[0]


def test_hob_starts_prime_to_the_teeth_do_not_warn(conn):
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, material, hardness, quality_grade, "
                 "module_kind) VALUES (90106, 'spur', 1.5, 49, 12, '20CrMnTi', 180, 8, 'normal')")
    program = instantiate_gear(conn, 90106)
    assert math.gcd(2, 49) == 1 and not [note for note in program.notes if "hunting" in note]


def test_cli_instantiate_says_the_bounded_feed_and_the_hunting_tooth_in_one_line_each(run):
    paper = run("instantiate", "--gear", 42)    # the paper's case: 8.11 mm/rev at m2, bounded to 3.0 (§C)
    bounded = [line for line in paper.stderr.splitlines() if line.startswith("note: ") and "bounded" in line]
    # then, its single cut being its last, bounded again by its grade's feed marks (§B6)
    table, marks = bounded[0], bounded[1:]
    assert paper.exit_code == 0 and "8.11" in table and "3.00" in table
    assert len(marks) == 1 and "feed marks" in marks[0] and "grade 7" in marks[0]
    batch = run("instantiate", "--gears", "46-46", "--json")
    assert any("common factor 2" in note for note in json.loads(batch.stdout)["notes"])


# --- process allowance (§B14) -----------------------------------------------------------

@pytest.mark.parametrize("cuts", [1, 2])
def test_the_allowance_raises_the_final_cut_and_is_recorded_in_the_job(conn, cuts):
    gear = load_gear(conn, 42)
    program = instantiate_gear(conn, 42, choices=Choices(cuts=cuts, allowance=0.25))
    params, cut_params = conn.execute("SELECT params, module_params FROM job WHERE id = %s",
                                      (program.job_id,)).fetchone()
    full_depth = (gear.root_diameter + 70.0) / 2          # H-M2-AA-R1, d_a0 70 (§B3)
    assert params["allowance"] == 0.25
    assert cut_params["cutmotion:2"]["cut_x"] == pytest.approx(full_depth + 0.25, abs=0.001)
    if cuts == 2:   # the rough cut leaves its finishing stock (0.3 mm at m2) above the final cut
        assert cut_params["cutmotion:1"]["cut_x"] == pytest.approx(full_depth + 0.25 + 0.3, abs=0.001)


def test_no_allowance_by_default(conn):
    program = instantiate_gear(conn, 42)
    params = conn.execute("SELECT params FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    assert params["allowance"] == 0


@pytest.mark.parametrize("allowance", [-0.1, 2.6])
def test_an_allowance_outside_0_to_2_5_mm_is_refused(allowance):
    with pytest.raises(EngineError, match=f"allowance {allowance:g} mm must be between 0 and 2.5"):
        Choices(allowance=allowance)


def test_cli_allowance_is_a_choice_of_a_new_job(run):
    made = run("instantiate", "--gear", 42, "--allowance", "2.5", "--json")
    assert made.exit_code == 0, made.output
    again = run("instantiate", "--job", json.loads(made.stdout)["job_id"], "--allowance", "1")
    assert again.exit_code == 1 and "--allowance applies to a new job" in again.stderr


# --- feeds edited into a stored job ---------------------------------------------------------

def test_a_stored_job_whose_feed_was_edited_beyond_the_table_is_refused_by_the_simulation(conn):
    """A feed per workpiece revolution above the §C roughing maximum overloads the hob's teeth
    whatever the pass (rough or finish): the program is wrong, not merely unusual, so the
    simulation every hobbing program passes refuses it in one line naming the cut and the
    maximum, and nothing is stored (it used to be made with only a note)."""
    from engine.programs.remake import instantiate_job

    job_id = instantiate_gear(conn, 42).job_id     # m2, 1-start hob, z 19, single cut
    params = conn.execute("SELECT params FROM job WHERE id = %s", (job_id,)).fetchone()[0]
    table_speed = params["n0"] * 1 / 19             # §B5: n2 = n0·z0/z2
    assert not instantiate_job(conn, job_id).notes  # as the engine made it: within the table
    conn.execute("UPDATE job SET module_params = jsonb_set(module_params, '{cutmotion:2,feed_axial}', '105') "
                 "WHERE id = %s", (job_id,))
    refusal = (rf"line \d+ 'G1 Z[-.0-9]+ F105.0': the pass feeds {105 / table_speed:.3f} mm per workpiece "
               r"revolution, above the 3 mm/rev roughing maximum for m2")
    with pytest.raises(EngineError, match=refusal) as refused:
        instantiate_job(conn, job_id)
    assert "\n" not in str(refused.value) and str(refused.value).endswith("nothing stored")
