"""Input that used to be lost or to crash (issue 13, item 8): each route refuses it in one line
that names the thing, with exit code 1, and the database is as it was. A quote left open no
longer swallows the rows after it; numbers that are no float (1e999, NaN) never reach the models
or the database; a server lost mid-batch is reported as such, with what was stored."""
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import ezdxf
import psycopg
import pytest
from helpers.drawings import seed_drawing
from psycopg.conninfo import conninfo_to_dict

from engine.drawings.entities import MAX_COORDINATE_MM
from engine.gears.records import load_gear
from engine.templates import template_csv

ROOT = Path(__file__).resolve().parents[1]
HEADER = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,tip_diameter,"
          "root_diameter,cone_angle,crowning,material,hardness,quality_grade,quantity")


def gear_rows(count=100):
    return [f"{90000 + k},spur,2,19,20,0,,20,,,,,40Cr,220,7,5" for k in range(count)]


def counts(url):
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM gear), (SELECT count(*) FROM job), "
                            "(SELECT count(*) FROM program), (SELECT count(*) FROM assembly), "
                            "(SELECT sum(template_version) FROM gear_class)").fetchone()


def refusal(result) -> str:
    assert result.exit_code == 1, result.output
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.output, result.stderr
    return result.stderr


# --- gear CSV ------------------------------------------------------------------------------------

@pytest.mark.parametrize("edit, words", [
    (lambda rows: rows.__setitem__(1, rows[1].replace("40Cr", '"40Cr')), "line 3: a quote opened here is never closed"),
    # closed again by a later quote: the record runs over lines 3 to 5
    (lambda rows: (rows.__setitem__(1, rows[1].replace("40Cr", '"40Cr')),
                   rows.__setitem__(3, rows[3].replace("40Cr", '40Cr"'))), "line 3: a quote opened on this line"),
    (lambda rows: rows.__setitem__(3, rows[3].replace(",220,", ",1e999,")), "line 5, column hardness: '1e999'"),
    (lambda rows: rows.__setitem__(3, rows[3].replace(",220,", ",900,")), "line 5, column hardness: 900 is outside"),
    (lambda rows: rows.__setitem__(3, rows[3].replace(",,20,,,,,40Cr", ",,1e999,,,,,40Cr")),
     "line 5, column face_width: '1e999'"),
])
def test_a_bad_gear_file_imports_nothing_and_names_the_line(read_only_run, tmp_path, edit, words):
    rows = gear_rows()
    edit(rows)
    (tmp_path / "gears.csv").write_text(HEADER + "\n" + "\n".join(rows) + "\n")
    before = counts(read_only_run.url)
    result = read_only_run("gears", "import", tmp_path / "gears.csv")
    assert result.exit_code == 1 and words in result.stderr, result.stderr
    assert "Traceback" not in result.output
    assert counts(read_only_run.url) == before


@pytest.mark.parametrize("value", ["1e999", "NaN", "Infinity"])
def test_a_gear_edited_in_sql_beyond_a_float_is_refused_before_any_model(run, value):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET hardness = %s::numeric WHERE id = 42", (value,))
        conn.commit()
    before = counts(run.url)
    message = refusal(run("instantiate", "--gear", 42))
    assert "gear 42: hardness" in message
    assert counts(run.url) == before


def test_a_gear_written_in_sql_without_diameters_gets_them_as_the_csv_computes_them(conn):
    conn.execute("UPDATE gear SET tip_diameter = NULL, root_diameter = NULL WHERE id = 42")
    gear = load_gear(conn, 42)
    tip = gear.module * gear.teeth + 2 * gear.module          # d + 2m for a spur gear
    assert (gear.tip_diameter, gear.root_diameter) == (pytest.approx(tip), pytest.approx(tip - 2 * 2.25 * gear.module))


# --- template CSV --------------------------------------------------------------------------------

def exported_spur(run) -> str:
    result = run("template", "export", "--class", "spur")
    assert result.exit_code == 0
    return result.stdout


def import_refused(run, path, words):
    before = counts(run.url)
    message = refusal(run("template", "import", "--class", "spur", path))
    assert words in message, message
    assert counts(run.url) == before


def test_an_unclosed_quote_in_a_template_is_refused_at_its_line(read_only_run, tmp_path):
    lines = exported_spur(read_only_run).splitlines(keepends=True)
    opened = next(number for number, line in enumerate(lines) if line.endswith('""",\n') and number > 3)
    lines[opened] = lines[opened][:-len('""",\n')] + '"",\n'     # the cell's closing quote is gone
    (tmp_path / "spur.csv").write_text("".join(lines))
    import_refused(read_only_run, tmp_path / "spur.csv", f"line {opened + 1}:")


def test_a_quote_closed_rows_later_is_refused_at_the_line_it_opens(read_only_run, tmp_path):
    text = "id,t,n,p_calc,s,o,p_emit\n10,main,1,,,\"'G90',\n20,main,1,,,'G0'\",\n30,main,1,,,'M30',\n"
    (tmp_path / "spur.csv").write_text(text)
    import_refused(read_only_run, tmp_path / "spur.csv", "line 2: a cell runs on into what looks like a row")


def test_a_template_that_is_not_utf8_names_the_line(read_only_run, tmp_path):
    text = exported_spur(read_only_run).replace("GEAR", "GEÄR", 1)
    line = text[:text.index("GEÄR")].count("\n") + 1
    (tmp_path / "spur.csv").write_bytes(text.encode("latin-1"))
    import_refused(read_only_run, tmp_path / "spur.csv", f"line {line}: not UTF-8")


def test_a_template_with_a_nul_names_the_line(read_only_run, tmp_path):
    text = exported_spur(read_only_run)
    line = text[:text.index("G90")].count("\n") + 1
    (tmp_path / "spur.csv").write_text(text.replace("G90", "G9\x000", 1))
    import_refused(read_only_run, tmp_path / "spur.csv", f"line {line}: holds a NUL")


def test_an_oversized_cell_names_the_line(read_only_run, tmp_path):
    text = exported_spur(read_only_run)
    line = text[:text.index('"G90 G71 G94"')].count("\n") + 1
    (tmp_path / "spur.csv").write_text(text.replace('"G90 G71 G94"', '"G90 G71 G94' + " " * 200_000 + '"', 1))
    import_refused(read_only_run, tmp_path / "spur.csv", f"line {line}: not valid CSV (field larger than field limit")


def test_an_oversized_template_file_is_refused_before_it_is_read(read_only_run, tmp_path, monkeypatch):
    text = exported_spur(read_only_run)
    monkeypatch.setattr(template_csv, "MAX_CSV_BYTES", len(text.encode()) - 1)
    (tmp_path / "spur.csv").write_text(text)
    import_refused(read_only_run, tmp_path / "spur.csv", "more than a template CSV may hold")


# --- DXF -----------------------------------------------------------------------------------------

def first(msp, kind, layer="0"):
    return next(entity for entity in msp if entity.dxftype() == kind and entity.dxf.layer == layer)


NAN, HUGE = math.nan, 1e308
REACH = f"within {MAX_COORDINATE_MM:g} mm"
DXF_EDITS = {
    "profile line NaN": (lambda msp: setattr(first(msp, "LINE").dxf, "start", (NAN, 0, 0)), "LINE", "not a number"),
    "profile line 1e308": (lambda msp: setattr(first(msp, "LINE").dxf, "end", (0, HUGE, 0)), "LINE", REACH),
    "tool path NaN": (lambda msp: setattr(first(msp, "LINE", "1").dxf, "start", (NAN, 0.9, 0)), "LINE", "not a number"),
    "thread line 1e308": (lambda msp: setattr(first(msp, "LINE", "3").dxf, "start", (-HUGE, 0.5, 0)), "LINE", REACH),
    "tool change NaN": (lambda msp: setattr(first(msp, "POINT").dxf, "location", (NAN, 1.5, 0)), "POINT",
                        "not a number"),
    "arc radius NaN": (lambda msp: setattr(first(msp, "ARC").dxf, "radius", NAN), "ARC", "radius holds nan"),
    "arc radius 1e308": (lambda msp: setattr(first(msp, "ARC").dxf, "radius", HUGE), "ARC", REACH),
    "block scale 1e308": (lambda msp: setattr(first(msp, "INSERT").dxf, "xscale", HUGE), "LINE", REACH),
    "block rotation NaN": (lambda msp: setattr(first(msp, "INSERT").dxf, "rotation", NAN), "INSERT", "not a number"),
    "bulge NaN": (lambda msp: first(msp, "LWPOLYLINE").set_points([(0, 0.5, 0), (-1, 0.5, NAN), (-2, 0.5, 0)],
                                                                   format="xyb"), "LWPOLYLINE", "not a number"),
}


@pytest.mark.parametrize("case", DXF_EDITS)
def test_a_drawing_with_coordinates_that_are_no_number_stores_no_job(read_only_run, tmp_path, case):
    edit, entity, words = DXF_EDITS[case]
    seed_drawing(tmp_path / "part.dxf")
    doc = ezdxf.readfile(tmp_path / "part.dxf")
    edit(doc.modelspace())
    doc.saveas(tmp_path / "bad.dxf")
    before = counts(read_only_run.url)
    message = refusal(read_only_run("import-dxf", tmp_path / "bad.dxf"))
    assert message.startswith(f"error: {entity} ") and words in message, message
    assert counts(read_only_run.url) == before


# --- the server lost -----------------------------------------------------------------------------

@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_server_lost_mid_batch_is_exit_1_and_says_nothing_was_stored(fresh_database_url):
    with psycopg.connect(fresh_database_url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, material, hardness, quality_grade) "
                     "SELECT 100000 + g, 'spur', 2, 19 + g % 40, 20, '40Cr', 170 + g % 100, 7 "
                     "FROM generate_series(1, 3000) g")
        conn.commit()
        before = counts(fresh_database_url)
    batch = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", fresh_database_url, "instantiate",
                              "--all"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    database = conninfo_to_dict(fresh_database_url)["dbname"]
    with psycopg.connect(fresh_database_url, autocommit=True) as admin:
        terminated = []
        while not terminated and batch.poll() is None:   # the batch plans 3,000 gears: about a minute
            time.sleep(0.5)
            terminated = admin.execute("SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = %s "
                                       "AND pid <> pg_backend_pid() AND state IS NOT NULL", (database,)).fetchall()
    stderr = batch.communicate(timeout=120)[1]
    assert terminated, f"the batch ended before its connection could be terminated: {stderr}"
    assert batch.returncode == 1 and stderr.count("\n") == 1, stderr
    assert "its transaction was rolled back, nothing of it was stored" in stderr
    assert counts(fresh_database_url) == before


def test_a_connection_lost_while_committing_says_the_outcome_is_unknown(fresh_database_url):
    from engine.cli.app import _database_failure_message

    with psycopg.connect(fresh_database_url) as conn, psycopg.connect(fresh_database_url, autocommit=True) as admin:
        conn.execute("UPDATE gear SET quantity = 7 WHERE id = 42")
        admin.execute("SELECT pg_terminate_backend(%s)", (conn.info.backend_pid,))
        with pytest.raises(psycopg.OperationalError) as lost:
            conn.commit()
    assert "whether the work was stored is unknown" in _database_failure_message(lost.value, "lost")
