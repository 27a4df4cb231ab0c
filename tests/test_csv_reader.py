"""The one CSV reader (engine.csv_reader) as users meet it: German Excel files (`;`, decimal commas),
malformed rows refused with their line and column, every kind of CSV phrased alike, and the gear
import's refusal of stored ids (unless --replace) and of diameters that contradict m_n, z, β and x."""
from __future__ import annotations

import math
import re

import psycopg
import pytest

from engine.errors import EngineError
from engine.gears.cases import seed_cases
from engine.gears.gear_geometry import DIAMETER_TOLERANCE, PROFILE_SHIFT_RANGE, TIP_SHORTENING_MAX
from engine.gears.gear_import import read_gears
from engine.gears.gear_store import import_gears, installed_classes
from engine.gears.hob_library import read_hobs
from engine.gears.units import import_units
from engine.library.nc_import import read_modules, read_params
from engine.templates.template_csv import read_csv

GEARS_COMMA = ("gear_id,gear_class,module,teeth,helix_angle,hand,face_width,tip_diameter,material\n"
               "90201,spur,2.5,40,0,,30,106.2,40Cr\n"
               "90202,helical,1.75,33,12.5,R,22.5,,\"42CrMo4, vergütet\"\n")
GEARS_SEMICOLON = ("gear_id;gear_class;module;teeth;helix_angle;hand;face_width;tip_diameter;material\n"
                   "90201;spur;2,5;40;0;;30;106,2;40Cr\n"
                   "90202;helical;1,75;33;12,5;R;22,5;;42CrMo4, vergütet\n")
HOBS_COMMA = ("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class\n"
              "H-T-1,2.5,20,1,80.5,110,R,AA\n")
HOBS_SEMICOLON = ("id;module;pressure_angle;starts;tip_diameter;length;hand;accuracy_class\n"
                  "H-T-1;2,5;20;1;80,5;110;R;AA\n")


def write(tmp_path, text: str, name: str = "gears.csv", encoding: str = "utf-8", newline: str = "\n"):
    path = tmp_path / name
    path.write_bytes(text.replace("\n", newline).encode(encoding))
    return path


def gear_rows(conn) -> list:
    return conn.execute("SELECT * FROM gear ORDER BY id").fetchall()


def refusal(action) -> str:
    """The whole message a refused read gives: the error and each problem line."""
    with pytest.raises(EngineError) as caught:
        action()
    return "\n".join([str(caught.value), *getattr(caught.value, "problems", [])])


def without_lines(gears: list[dict]) -> list[dict]:
    return [{key: value for key, value in gear.items() if key != "line"} for gear in gears]


# --- German Excel: `;` and decimal commas ---------------------------------------------------

def test_a_semicolon_file_with_decimal_commas_reads_as_the_comma_file(conn, tmp_path):
    classes = installed_classes(conn)
    comma = read_gears(write(tmp_path, GEARS_COMMA, "comma.csv"), classes)
    semicolon = read_gears(write(tmp_path, GEARS_SEMICOLON, "semicolon.csv"), classes)
    assert without_lines(semicolon) == without_lines(comma)
    assert str(semicolon[0]["module"]) == "2.5" and str(semicolon[1]["helix_angle"]) == "12.5"
    assert semicolon[1]["material"] == "42CrMo4, vergütet"   # a comma in a text cell stays text
    assert read_hobs(write(tmp_path, HOBS_SEMICOLON, "hobs.csv")) == read_hobs(write(tmp_path, HOBS_COMMA, "h.csv"))


def test_a_semicolon_file_imports_the_values_of_the_comma_file(conn, tmp_path):
    import_gears(conn, write(tmp_path, GEARS_SEMICOLON, "semicolon.csv"))
    from_semicolon = gear_rows(conn)
    conn.execute("DELETE FROM gear WHERE id IN (90201, 90202)")
    import_gears(conn, write(tmp_path, GEARS_COMMA, "comma.csv"))
    assert gear_rows(conn) == from_semicolon


def test_excel_s_byte_order_mark_crlf_and_blank_trailing_lines_are_read(conn, tmp_path):
    path = write(tmp_path, GEARS_SEMICOLON + "\n\n;;;;;;;;\n\n", encoding="utf-8-sig", newline="\r\n")
    gears = read_gears(path, installed_classes(conn))
    assert [gear["gear_id"] for gear in gears] == [90201, 90202]
    assert without_lines(gears) == without_lines(read_gears(write(tmp_path, GEARS_COMMA, "c.csv"),
                                                            installed_classes(conn)))


def test_a_decimal_comma_in_a_comma_file_is_said_not_guessed(conn, tmp_path):
    split = GEARS_COMMA.replace("90201,spur,2.5,", "90201,spur,2,5,")
    message = refusal(lambda: import_gears(conn, write(tmp_path, split)))
    assert "line 2: 10 cells, but the header names 9 columns" in message
    assert "a value like 2,5 looks like a decimal comma that split into two cells: write 2.5" in message
    quoted = GEARS_COMMA.replace("90201,spur,2.5,", '90201,spur,"2,5",')
    message = refusal(lambda: import_gears(conn, write(tmp_path, quoted)))
    assert (", line 2, column module: '2,5' has a decimal comma, but this file separates its columns with ','; "
            "write 2.5, or save the file with ';' between the columns") in message


def test_a_header_with_both_separators_is_refused(conn, tmp_path):
    message = refusal(lambda: import_gears(conn, write(tmp_path, "gear_id;module,teeth;face_width\n1;2;19;20\n")))
    assert message.endswith(", line 1: the header holds both ',' and ';'; separate the columns with one of them")


# --- malformed rows: refused with line (and column), nothing stored ------------------------

MALFORMED = {
    "a cell too many": ("90201,spur,2.5,40,0,,30,106.2,40Cr,7", "line 2: 10 cells, but the header names 9 columns"),
    "a cell too few": ("90201,spur,2.5,40,0,30,106.2,40Cr", "line 2: 8 cells, but the header names 9 columns"),
    "an unclosed quote": ('90201,spur,2.5,40,0,,30,106.2,"40Cr', "line 2: a quote opened on this line is not closed"),
    "an unclosed quote on a later row": ('90201,spur,2.5,40,0,,30,106.2,40Cr\n90203,spur,2,19,0,,20,,"45',
                                         "line 3: a quote opened on this line is not closed on it"),
    "a quote closed lines later": ('90201,spur,2.5,40,0,,30,106.2,"40Cr\n90203,spur,2,19,0,,20,,45"',
                                   "line 2: a quote opened on this line is closed only on line 3"),
    "a non-number": ("90201,spur,2.5,40,0,,30,106.2x,40Cr",
                     "line 2, column tip_diameter: '106.2x' is not a number; write a number in mm like 2.5"),
}


@pytest.mark.parametrize("row, words", MALFORMED.values(), ids=MALFORMED.keys())
def test_a_malformed_row_is_refused_naming_its_line_and_nothing_is_stored(conn, tmp_path, row, words):
    header, good = GEARS_COMMA.splitlines()[0], GEARS_COMMA.splitlines()[2]
    path = write(tmp_path, f"{header}\n{row}\n{good}\n")
    before = gear_rows(conn)
    message = refusal(lambda: import_gears(conn, path))
    assert f"{path}, {words}" in message
    assert gear_rows(conn) == before


# --- every kind of CSV through the one reader ------------------------------------------------

def _units(conn, path):
    import_units(conn, path)


def _cases(conn, path):
    seed_cases(conn, path)


KINDS = {   # kind: (read, header, a row with a bad number, its column, the type said)
    "gears": (lambda conn, path: import_gears(conn, path), "gear_id,module,teeth,face_width", "1,two,19,20",
              "module", "is not a number"),
    "units": (_units, "gear_id,unit,teeth,face_width,z_top", "42,2,19,wide,-75", "face_width", "is not a number"),
    "hobs": (lambda conn, path: read_hobs(path), "id,module,pressure_angle,starts,tip_diameter,length,hand,"
             "accuracy_class", "H-X,two,20,1,70,100,R,AA", "module", "is not a number"),
    "cases": (_cases, "module,teeth,material,hob_material,hob_starts,hob_tip_diameter,cut,hob_speed,axial_feed,"
              "radial_feed", "two,19,40Cr,HSS,1,70,rough,246,105,36", "module", "is not a number"),
    "templates": (lambda conn, path: read_csv(path), "id,t,n,p_calc,s,o,p_emit", "ten,main,1,,'G90',,",
                  "id", "is not a whole number"),
    "module types": (lambda conn, path: read_modules(path), "line_no,t", "first,main", "line_no",
                     "is not a whole number"),
}


@pytest.mark.parametrize("kind", KINDS)
def test_every_kind_of_csv_says_a_bad_cell_alike(conn, tmp_path, kind):
    read, header, row, column, said = KINDS[kind]
    path = write(tmp_path, f"{header}\n{row}\n", f"{kind}.csv")
    message = refusal(lambda: read(conn, path))
    assert re.search(rf"^{re.escape(str(path))}, line 2, column {column}: '[^']*' {said}; write ", message,
                     re.M), message


@pytest.mark.parametrize("kind", [*KINDS, "parameters"])
def test_every_kind_of_csv_refuses_a_short_row_alike(conn, tmp_path, kind):
    read, header, row, _, _ = KINDS.get(kind, (lambda conn, path: read_params(path), "name,value", "z2", "", ""))
    short = row.rsplit(",", 1)[0] if "," in row else row
    path = write(tmp_path, f"{header}\n{short}\n", f"{kind}.csv")
    cells, columns = short.count(",") + 1, header.count(",") + 1
    message = refusal(lambda: read(conn, path))
    assert f"{path}, line 2: {cells} cells, but the header names {columns} columns; give one cell per column" in message


def test_parameters_read_a_decimal_comma_in_a_semicolon_file(tmp_path):
    assert read_params(write(tmp_path, "name;value\nallowance;0,25\nmode;T\n", "params.csv")) == {
        "allowance": 0.25, "mode": "T"}


# --- gears import: a stored gear_id is refused unless --replace ------------------------------

def stored_gear(url, gear_id: int):
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT module, teeth, tip_diameter, root_diameter FROM gear WHERE id = %s",
                            (gear_id,)).fetchone()


def test_gear_42_is_not_overwritten_without_replace_and_is_with_it(run, tmp_path):
    path = write(tmp_path, "gear_id,gear_class,module,teeth,face_width\n42,spur,3,19,20\n")
    before = stored_gear(run.url, 42)
    assert before[0] == 2   # the seeded gear 42 has module 2

    refused = run("gears", "import", path)
    assert refused.exit_code == 1
    assert (f"{path}, line 2, column gear_id: gear 42 already exists; give a new gear_id, or import with "
            "--replace to overwrite it") in refused.stderr
    assert stored_gear(run.url, 42) == before

    replaced = run("gears", "import", path, "--replace")
    assert replaced.exit_code == 0, replaced.output
    assert "gear 42: module 2 → 3" in replaced.stdout.splitlines()
    # m = 3, z = 19: d = 57, tip = d + 2m = 63, root = tip − 2·2.25·m = 49.5
    assert "gear 42: tip_diameter 42 → 63" in replaced.stdout.splitlines()
    assert stored_gear(run.url, 42) == (3, 19, 63, 49.5)


def test_replace_prints_each_changed_field_in_json_too(run, tmp_path):
    path = write(tmp_path, "gear_id,gear_class,module,teeth,face_width,tip_diameter\n42,spur,2,19,25,42\n")
    result = run("gears", "import", path, "--replace", "--json")
    assert result.exit_code == 0 and result.stdout.count("\n") == 1
    changes = {change["field"]: (change["old"], change["new"])
               for change in __import__("json").loads(result.stdout)["changes"]}
    assert changes["face_width"] == (20, 25)
    assert "module" not in changes and "tip_diameter" not in changes


# --- geometry: diameters against m_n, z, β and x ---------------------------------------------

def reference(module, teeth, beta=0.0):
    return module * teeth / math.cos(math.radians(beta))


def tip(module, teeth, beta=0.0, x=0.0):
    return reference(module, teeth, beta) + 2 * module * (1 + x)


def root(module, teeth, beta=0.0, x=0.0):
    return reference(module, teeth, beta) - 2 * module * (1.25 - x)


HEADER = ("gear_id,gear_class,module,teeth,helix_angle,hand,face_width,tip_diameter,root_diameter,"
          "profile_shift,module_kind")


def test_diameters_that_fit_the_formulas_are_stored_with_their_profile_shift(conn, tmp_path):
    da, df = round(tip(3, 41, 15, 0.2), 2), round(root(3, 41, 15, 0.2), 2)
    spur_tip = round(tip(2, 19, 0, 0.125), 2)   # reference §D: d_a = 42.5 fits x = +0.125
    path = write(tmp_path,
                 f"{HEADER}\n90211,helical,3,41,15,R,30,{da},{df},0.2,\n90212,spur,2,19,0,,20,{spur_tip},,,\n")
    import_gears(conn, path)
    stored = conn.execute("SELECT tip_diameter, root_diameter, profile_shift FROM gear WHERE id = 90211").fetchone()
    assert [float(value) for value in stored] == [da, df, 0.2]


def test_a_tip_diameter_of_another_module_is_refused_with_formula_value_and_tolerance(conn, tmp_path):
    path = write(tmp_path, f"{HEADER}\n90213,spur,3,19,0,,20,42,,,\n")   # gear 42's tip, given module 3
    low_x, high_x = PROFILE_SHIFT_RANGE
    low = tip(3, 19, 0, low_x) - 2 * TIP_SHORTENING_MAX * 3
    high = tip(3, 19, 0, high_x)
    message = refusal(lambda: import_gears(conn, path))
    assert (f"{path}, line 2, column tip_diameter: 42 contradicts d_a = m_n·z/cos β + 2·m_n·(1 + x + k) with x in "
            f"{low_x:g} … {high_x:g}, k ≥ −{TIP_SHORTENING_MAX:g} = {low:.3f} … {high:.3f} mm for m_n 3, z 19, β 0° "
            f"(tolerance ±{DIAMETER_TOLERANCE} mm); check module, teeth") in message
    assert not conn.execute("SELECT 1 FROM gear WHERE id = 90213").fetchone()


def test_a_given_profile_shift_pins_the_diameters_to_the_tolerance(conn, tmp_path):
    da = tip(2, 30, 0, 0.3)
    near = f"{HEADER}\n90214,spur,2,30,0,,20,{da + DIAMETER_TOLERANCE / 2:.3f},,0.3,\n"
    import_gears(conn, write(tmp_path, near))
    far = f"{HEADER}\n90215,spur,2,30,0,,20,{da + 3 * DIAMETER_TOLERANCE:.3f},,0.3,\n"
    message = refusal(lambda: import_gears(conn, write(tmp_path, far, "far.csv")))
    assert f"column tip_diameter: {da + 3 * DIAMETER_TOLERANCE:.3f} contradicts" in message
    shortened = da - 2 * TIP_SHORTENING_MAX * 2   # a tip may be shortened by k·m_n, never lengthened
    assert (f"= {shortened:.3f} … {da:.3f} mm for m_n 2, z 30, β 0°, x 0.3 "
            f"(tolerance ±{DIAMETER_TOLERANCE} mm)") in message


def test_a_tip_and_root_less_than_a_tooth_depth_apart_are_refused(conn, tmp_path):
    da = tip(2, 30)
    path = write(tmp_path, f"{HEADER}\n90216,spur,2,30,0,,20,{da:g},{da - 6:g},,\n")   # full depth is 2·2.25·2 = 9
    message = refusal(lambda: import_gears(conn, path))
    assert "column root_diameter: 58 (tip_diameter − root_diameter = 6) contradicts the tooth depth" in message


def test_worm_wheels_and_taper_gears_are_not_held_to_the_cylindrical_formulas(conn, tmp_path):
    far = tip(3, 40, 4.05) + 10   # a throat or large-end diameter far from the cylindrical tip
    path = write(tmp_path, f"{HEADER}\n90217,worm_wheel,3,40,4.05,R,25,{far:.2f},,,normal\n")
    import_gears(conn, path)
    taper = write(tmp_path, "gear_id,module,teeth,face_width,tip_diameter,cone_angle\n90218,2,19,20,46,6.5\n", "t.csv")
    import_gears(conn, taper)
    assert conn.execute("SELECT count(*) FROM gear WHERE id IN (90217, 90218)").fetchone()[0] == 2
    helical = write(tmp_path, f"{HEADER}\n90219,helical,3,40,4.05,R,25,{far:.2f},,,\n", "h.csv")
    assert "column tip_diameter" in refusal(lambda: import_gears(conn, helical))


def test_a_further_unit_of_a_duplex_gear_is_held_to_the_formulas_of_its_module(conn, tmp_path):
    # gear 54 (seeded): duplex, m = 2; a spur unit of z = 19 has d_a = 2·19 + 2·2 = 42 at x = 0
    good = write(tmp_path, f"gear_id,unit,teeth,face_width,tip_diameter,z_top\n54,2,19,15,{tip(2, 19):g},-75\n",
                 "u.csv")
    assert import_units(conn, good) == 1
    wrong = write(tmp_path, f"gear_id,unit,teeth,face_width,tip_diameter,z_top\n54,2,19,15,{tip(3, 19):g},-75\n",
                  "w.csv")
    assert f"line 2, column tip_diameter: {tip(3, 19):g} contradicts d_a" in refusal(lambda: import_units(conn, wrong))
