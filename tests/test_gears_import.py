"""Gear CSV import (design notes §9) and classification, against a real PostgreSQL."""
from __future__ import annotations

import math
import re
from decimal import Decimal

import pytest

from engine.errors import EngineError
from engine.gears.classify import RULES, classify, classify_installed
from engine.gears.gear_import import GearImportError, derived_diameters, read_gears
from engine.gears.gear_store import import_gears

HEADER = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,tip_diameter,root_diameter,"
          "cone_angle,crowning,material,hardness,quality_grade,quantity")
SPUR = "90001,,2,19,,,,20,,,,,40Cr,220,7,5"
HELICAL = "90002,,3,30,20,15,R,25.125,,,,,,,,"
GOOD = f"{HEADER}\n{SPUR}\n{HELICAL}\n"


def write(tmp_path, text: str, name: str = "gears.csv", encoding: str = "utf-8"):
    path = tmp_path / name
    path.write_bytes(text.encode(encoding))
    return path


def gear_count(conn) -> int:
    return conn.execute("SELECT count(*) FROM gear").fetchone()[0]


def stored(conn, gear_id: int) -> dict:
    cursor = conn.execute("SELECT * FROM gear WHERE id = %s", (gear_id,))
    names = [column.name for column in cursor.description]
    row = cursor.fetchone()
    return dict(zip(names, row)) if row else {}


# --- good files --------------------------------------------------------------------------

def test_good_file_imports_every_row_with_its_values(conn, tmp_path):
    before = gear_count(conn)
    assert import_gears(conn, write(tmp_path, GOOD)).imported == 2
    assert gear_count(conn) == before + 2

    spur = stored(conn, 90001)
    # Spur m=2 z=19: d = m·z = 38, tip = d + 2m = 42, root = tip − 2·2.25·m = 42 − 9 = 33.
    assert spur["tip_diameter"] == 42 and spur["root_diameter"] == 33
    assert spur["gear_class"] == "spur" and spur["hand"] is None
    assert spur["pressure_angle"] == 20 and spur["helix_angle"] == 0
    assert (spur["material"], spur["hardness"], spur["quality_grade"], spur["quantity"]) == (
        "40Cr", 220, 7, 5)
    assert spur["cone_angle"] is None and spur["crowning"] is None

    helical = stored(conn, 90002)
    # Helical m=3 z=30 β=15°: d = m·z / cos β, tip = d + 2m, root = tip − 4.5m.
    reference = 3 * 30 / math.cos(math.radians(15))
    assert helical["gear_class"] == "helical" and helical["hand"] == "R"
    assert float(helical["tip_diameter"]) == pytest.approx(reference + 6, abs=1e-9)
    assert float(helical["root_diameter"]) == pytest.approx(reference + 6 - 13.5, abs=1e-9)
    assert helical["face_width"] == Decimal("25.125")  # stored as written, not rounded


def test_given_tip_keeps_full_tooth_depth_and_numbers_stay_as_written(conn, tmp_path):
    text = f"{HEADER}\n90003,spur,2.50,40,,,,30,106.2,,,,,,,\n90004,spur,2,19,,,,20,42.4,32.95,,,,,,\n"
    import_gears(conn, write(tmp_path, text))
    shifted = stored(conn, 90003)
    # Given tip 106.2 (profile shift): root = 106.2 − 2·2.25·2.5 = 106.2 − 11.25 = 94.95.
    assert shifted["module"] == Decimal("2.50") and shifted["root_diameter"] == Decimal("94.95")
    assert stored(conn, 90004)["root_diameter"] == Decimal("32.95")


def test_reimport_with_replace_updates_the_gears(conn, tmp_path):
    import_gears(conn, write(tmp_path, GOOD))
    before = gear_count(conn)
    corrected = GOOD.replace("90001,,2,19,", "90001,,2,21,")
    assert import_gears(conn, write(tmp_path, corrected, "corrected.csv"), replace=True).imported == 2
    assert gear_count(conn) == before
    spur = stored(conn, 90001)
    # z=21: d = 42, tip = 46, root = 46 − 9 = 37.
    assert (spur["teeth"], spur["tip_diameter"], spur["root_diameter"]) == (21, 46, 37)


def test_any_column_order_whitespace_and_optional_columns_left_out(conn, tmp_path):
    text = " teeth , face_width ,gear_id, module \n 19 , 20 , 90005 , 2 \n"
    assert import_gears(conn, write(tmp_path, text)).imported == 1
    gear = stored(conn, 90005)
    assert (gear["teeth"], gear["module"], gear["gear_class"]) == (19, 2, "spur")


def test_file_with_byte_order_mark_imports(conn, tmp_path):
    assert import_gears(conn, write(tmp_path, GOOD, encoding="utf-8-sig")).imported == 2
    assert stored(conn, 90001)["gear_class"] == "spur"


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_ten_thousand_rows_import(conn, tmp_path):
    rows = [f"{100000 + n},,2,{17 + n % 80},,{15 if n % 2 else ''},{'L' if n % 2 else ''},20,,,,,,,,"
            for n in range(10_000)]
    before = gear_count(conn)
    assert import_gears(conn, write(tmp_path, "\n".join([HEADER] + rows) + "\n")).imported == 10_000
    assert gear_count(conn) == before + 10_000
    assert conn.execute("SELECT count(*) FROM gear WHERE id >= 100000 AND gear_class = 'helical'"
                        ).fetchone()[0] == 5_000


# --- classification ----------------------------------------------------------------------

def test_classification_of_an_empty_gear_class_with_its_explanation():
    helical = classify({"helix_angle": Decimal(15), "cone_angle": None, "crowning": None})
    assert helical.gear_class == "helical"
    assert [question for question, _ in helical.path] == [rule.question for rule in RULES]
    assert [answer.split()[0] for _, answer in helical.path] == ["no", "no", "no", "yes"]
    assert helical.path[-1][1] == "yes (helix_angle = 15)"
    assert helical.explain().endswith("yes (helix_angle = 15) → helical")

    spur = classify({"helix_angle": 0})
    assert spur.gear_class == "spur"
    assert [answer for _, answer in spur.path] == [
        "no (not given)", "no (not given)", "no (not given)", "no (helix_angle = 0)"]


@pytest.mark.parametrize("gear, expected, steps", [
    ({"units": 1, "cone_angle": 0}, "duplex", 1),
    ({"cone_angle": 3, "helix_angle": 15}, "taper", 2),
    ({"cone_angle": 0, "crowning": "0.02"}, "crowned", 3),
    ({"crowning": 0, "helix_angle": 0}, "spur", 4),
    ({"crowning": "", "helix_angle": "12.5"}, "helical", 4),
    ({"units": 0, "crowning": "", "helix_angle": "12.5"}, "helical", 4),
])
def test_classification_rules_in_order(gear, expected, steps):
    classification = classify(gear)
    assert classification.gear_class == expected and len(classification.path) == steps


def test_classified_class_not_installed_is_an_error(tmp_path):
    with pytest.raises(EngineError, match="gear 7: classified as taper, but no gear class 'taper' "
                                          "is installed; give gear_class explicitly"):
        classify_installed({"gear_id": 7, "cone_angle": 2}, {"spur", "helical"})
    path = write(tmp_path, "gear_id,module,teeth,face_width,cone_angle\n7,2,19,20,2\n")
    with pytest.raises(GearImportError) as caught:
        read_gears(path, {"spur": True, "helical": True})
    assert caught.value.problems == [
        f"{path}, line 2, column gear_class: gear 7: classified as taper, but no gear class 'taper' is installed; give "
        "gear_class explicitly or add the class (engine template import --class taper …)"]


# --- bad files: every problem with its line, nothing stored ------------------------------

BAD_ROWS = [
    ("90009,,abc,19,,,,20,,,,,,,,", "line 3, column module: 'abc' is not a number"),
    ("90009,,,19,,,,20,,,,,,,,", "line 3, column module: is missing"),
    ("90009,,2,19.5,,,,20,,,,,,,,", "line 3, column teeth: '19.5' is not a positive whole number"),
    ("90009,,2,0,,,,20,,,,,,,,", "line 3, column teeth: '0' is not a positive whole number"),
    ("90009,,2,19,,,,0,,,,,,,,", "line 3, column face_width: 0 must be greater than 0"),
    ("90009,,-2,19,,,,20,,,,,,,,", "line 3, column module: -2 must be greater than 0"),
    ("90009,,2,19,,,,20,-42,,,,,,,", "line 3, column tip_diameter: -42 must be greater than 0"),
    ("90009,,2,19,,60,R,20,,,,,,,,", "line 3, column helix_angle: 60 is outside [0, 60)"),
    ("90009,,2,19,,-5,R,20,,,,,,,,", "line 3, column helix_angle: -5 is outside [0, 60)"),
    ("90009,,2,19,,15,X,20,,,,,,,,", "line 3, column hand: 'X' must be L or R"),
    ("90009,,2,19,,15,,20,,,,,,,,", "line 3, column hand: is missing; a helical gear (helix_angle 15)"),
    ("90009,bevelx,2,19,,,,20,,,,,,,,",
     "line 3, column gear_class: gear class 'bevelx' does not exist; known leaf classes: "),
    ("90009,gear,2,19,,,,20,,,,,,,,", "line 3, column gear_class: gear class 'gear' is not a leaf class"),
    ("90001,,2,19,,,,20,,,,,,,,", "line 3, column gear_id: 90001 is already on line 2"),
    ("90009,,2,19,,,,20,,,,,,,13,", "line 3, column quality_grade: 13 is outside 1..12"),
    ("90009,,2,19,,,,20,,,,,,,0,", "line 3, column quality_grade: 0 is outside 1..12"),
    ("90009,,2,19,,,,20,40,41,,,,,,",
     "line 3, column root_diameter: 41 contradicts d_f = m_n·z/cos β − 2·m_n·(h*f − x) with x in -1 … 1.5"),
    ("90009,,2,19,,,,20,,43,,,,,,",
     "line 3, column root_diameter: 43 contradicts d_f = m_n·z/cos β − 2·m_n·(h*f − x) with x in -1 … 1.5"),
    ("90009,,2,19,,,,20,,,,,,,,,extra", "line 3: 17 cells, but the header names 16 columns"),
]


@pytest.mark.parametrize("bad_row, message", BAD_ROWS, ids=[m.split(": ", 1)[1][:40] for _, m in BAD_ROWS])
def test_a_bad_row_is_reported_with_its_line_and_nothing_is_stored(conn, tmp_path, bad_row, message):
    path = write(tmp_path, f"{HEADER}\n{SPUR}\n{bad_row}\n{HELICAL}\n")
    before = gear_count(conn)
    with pytest.raises(GearImportError) as caught:
        import_gears(conn, path)
    assert str(caught.value) == f"{path}: 1 bad row(s); nothing imported"
    assert caught.value.problems == [caught.value.problems[0]]
    assert caught.value.problems[0].startswith(f"{path}, {message}"), caught.value.problems
    assert gear_count(conn) == before and not stored(conn, 90001)


def test_all_problems_of_all_rows_are_collected_in_file_order(conn, tmp_path):
    text = (f"{HEADER}\n{SPUR}\n"
            "90010,,2,19,,75,X,20,,,,,,,,\n"
            '90011,,2,19,,,,20,,,,,40Cr,,,\n\n'  # a blank line 5 still counts (a quoted line break is refused)
            "90012,bevelx,abc,19,,,,20,,,,,,,,\n")
    path = write(tmp_path, text)
    with pytest.raises(GearImportError) as caught:
        import_gears(conn, path)
    assert str(caught.value) == f"{path}: 2 bad row(s); nothing imported"
    assert ([re.search(r", (line \d+)", problem)[1] for problem in caught.value.problems]
            == ["line 3"] * 2 + ["line 6"] * 2)
    assert caught.value.problems[0] == (f"{path}, line 3, column helix_angle: 75 is outside [0, 60); "
                                        "write a number in degrees like 2.5")
    assert caught.value.problems[1] == f"{path}, line 3, column hand: 'X' must be L or R; write L or R (the helix hand)"
    assert caught.value.problems[3].startswith(f"{path}, line 6, column gear_class: gear class 'bevelx' does not exist")


def test_unknown_and_missing_columns_are_named(conn, tmp_path):
    before = gear_count(conn)
    path = write(tmp_path, f"{HEADER},colour,size\n{SPUR},red,9\n")
    with pytest.raises(EngineError, match=r"unknown column\(s\) colour, size"):
        import_gears(conn, path)
    path = write(tmp_path, "gear_id,teeth,material\n90001,19,40Cr\n")
    with pytest.raises(EngineError, match=r"missing required column\(s\) module, face_width"):
        import_gears(conn, path)
    assert gear_count(conn) == before


@pytest.mark.parametrize("text", ["", f"{HEADER}\n", f"\n{HEADER}\n\n,,,\n"])
def test_a_file_without_gear_rows_is_an_error(conn, tmp_path, text):
    path = write(tmp_path, text)
    with pytest.raises(EngineError, match=f"^{re.escape(str(path))}(: is empty| has no gear rows); "):
        import_gears(conn, path)


def test_a_missing_file_is_named(conn, tmp_path):
    with pytest.raises(EngineError, match="nowhere.csv"):
        import_gears(conn, tmp_path / "nowhere.csv")


def test_a_file_that_is_not_utf8_is_named(conn, tmp_path):
    path = write(tmp_path, f"{HEADER}\n90001,,2,19,,,,20,,,,,Stahl ä,,,\n", encoding="latin-1")
    with pytest.raises(EngineError, match="not UTF-8"):
        import_gears(conn, path)


# --- geometry ----------------------------------------------------------------------------

def test_derived_diameters_with_plain_numbers():
    # Spur m=2 z=19: tip = 38 + 4 = 42, root = 42 − 9 = 33.
    assert derived_diameters(2.0, 19, 0, None, None) == (42.0, 33.0)
    assert derived_diameters(Decimal(2), 19, Decimal(0), None, None) == (42, 33)
    # Given diameters win; a given tip alone sets root = tip − 4.5m.
    assert derived_diameters(2.0, 19, 0, 43.0, 34.5) == (43.0, 34.5)
    assert derived_diameters(2.0, 19, 0, 43.0, None) == (43.0, 34.0)
    tip, root = derived_diameters(3.0, 30, 15.0, None, None)
    assert tip == pytest.approx(90 / math.cos(math.radians(15)) + 6)
    assert tip - root == pytest.approx(13.5)
