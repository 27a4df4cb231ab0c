"""Safe names (issue 13): program, drawing, hob, class and machine names are checked where they
enter (CSV imports, DXF import, options, SQL) against engine/names.py, refused in one line with
exit 1 and nothing stored, never altered; and a line break put into a name, a job parameter or a
template row never reaches a stored program or a file."""
from __future__ import annotations

import shutil

import psycopg
import pytest
from helpers.drawings import seed_drawing
from psycopg.errors import CheckViolation

from engine.db.migrate import migrate
from engine.errors import EngineError
from engine.names import NAME_RULES, is_safe
from engine.paths import MIGRATIONS_DIR
from engine.programs.instantiate import instantiate_gear
from engine.turning.model import check_job_params

INJECTED = "G0 X9999 Z-9999"    # the block that reached stored programs through each route
NEWLINE = f"\n{INJECTED}"

LINE_BREAK_IN_CELL = "a cell holds no line break"   # the CSV reader's refusal
NUL_IN_FILE = "holds a NUL character"   # the CSV reader's refusal of a file with a NUL, before any cell

# Per kind: names its rule refuses (a line break, a path, one character too many, bad first
# characters, NUL) and names it takes, at the edges of the rule.
UNSAFE = {
    "program": ["GEAR42" + NEWLINE, "../../x", "A" * 25, "1AB", "A1B", "_1AB", "AB\x00C", "AB\rC", "", "AB-1"],
    "class": ["spur" + NEWLINE, "../../x", "a" * 64, "1abc", "_abc", "Spur", "sp\x00ur", "sp ur", ""],
    "hob": ["H1" + NEWLINE, "../../x", "H" * 33, "-H1", ".H1", "H\x00", "H 1", "H(1)", ""],
    "machine": ["m" + NEWLINE, "../../x", "m" * 33, "1m", "-m", "m\x00", "m;1", ""],
    "drawing": ["part" + NEWLINE + ".dxf", "a" * 81, ".part.dxf", "-part.dxf", "part(1).dxf", "part;1.dxf",
                "p\x00.dxf", "p/q.dxf", ""],
}
SAFE = {
    "program": ["AB", "_A", "GEAR42", "gear42", "A" * 24, "_A" + "1" * 22, "EMCO_TESTNEGDXF_R14"],
    "class": ["spur", "worm_wheel", "turning_840d", "a" * 63, "x1"],
    "hob": ["H-M1.5-A-R2", "H-WW-M3-R1", "1", "H" * 32],
    "machine": ["hobber-840d", "lathe-iso", "M" * 32, "Lathe_2.b"],
    "drawing": ["part.dxf", "seed part 2.dxf", "emco_lathe_testNegDXF_R14.dxf", "1.dxf", "a" * 80],
}


def test_the_rules_refuse_and_take_what_they_say():
    for kind in NAME_RULES:
        assert [name for name in UNSAFE[kind] if is_safe(kind, name)] == [], kind
        assert [name for name in SAFE[kind] if not is_safe(kind, name)] == [], kind
    assert not is_safe("program", None) and not is_safe("program", 42)


def test_the_database_holds_the_same_rules(conn):
    samples = {name for names in (*UNSAFE.values(), *SAFE.values()) for name in names if "\x00" not in name}
    samples |= {"É1", "AΒ", "ＡＢ", "A\u2028B", "AB\n", "\nAB", "ab\t", "a.b", "a b"}
    for kind in NAME_RULES:
        for name in sorted(samples):
            in_sql = conn.execute("SELECT safe_name(%s, %s)", (kind, name)).fetchone()[0]
            assert in_sql == is_safe(kind, name), (kind, name)


# --- each entry refuses an unsafe name, one line, exit 1, nothing stored -----------------------

def counts(url) -> tuple:
    with psycopg.connect(url) as conn:
        return conn.execute("""SELECT (SELECT count(*) FROM gear), (SELECT count(*) FROM gear_class),
                                      (SELECT count(*) FROM hob), (SELECT count(*) FROM machine),
                                      (SELECT count(*) FROM job), (SELECT count(*) FROM program)""").fetchone()


def refused(result) -> str:
    """Exit 1, no stack trace, and every line of the message an engine line: no name's line break
    reaches the terminal as a line of its own."""
    assert result.exit_code == 1, result.output
    lines = result.stderr.rstrip("\n").split("\n")
    assert "Traceback" not in result.output and lines[0].startswith("error: ")
    assert all(line.startswith("  ") for line in lines[1:]), lines   # a CSV file's problems, one per line
    return result.stderr


def write_csv(path, header: str, row: list[str]) -> None:
    import csv

    with open(path, "w", newline="", encoding="utf-8") as file:
        file.write(header + "\n")
        csv.writer(file).writerow(row)


GEAR_HEADER = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,tip_diameter,"
               "root_diameter,cone_angle,crowning,material,hardness,quality_grade,quantity")
HOB_HEADER = "id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,material,coating,purpose"


# An empty class is "classify it" (design notes §9); a class is read in lower case (Spur is spur).
@pytest.mark.parametrize("name", [name for name in UNSAFE["class"] if name and name != "Spur"])
def test_a_gear_csv_with_an_unsafe_class_is_refused(read_only_run, tmp_path, name):
    write_csv(tmp_path / "gears.csv", GEAR_HEADER, ["900", name, "2", "19", "20", "0", "", "20", "42", "", "", "",
                                                   "40Cr", "250", "7", "50"])
    before = counts(read_only_run.url)
    message = refused(read_only_run("gears", "import", tmp_path / "gears.csv"))
    assert "gear_class" in message or LINE_BREAK_IN_CELL in message or NUL_IN_FILE in message   # the reader first
    assert counts(read_only_run.url) == before


@pytest.mark.parametrize("name", UNSAFE["hob"][:-1])   # an empty id is "id is missing"
def test_hobs_import_and_add_refuse_an_unsafe_id(read_only_run, tmp_path, name):
    write_csv(tmp_path / "hobs.csv", HOB_HEADER, [name, "2", "20", "1", "70", "100", "R", "AA", "HSS", "TiN",
                                                 "cylindrical"])
    before = counts(read_only_run.url)
    message = refused(read_only_run("hobs", "import", tmp_path / "hobs.csv"))
    # the reader first
    assert "not a safe hob id" in message or LINE_BREAK_IN_CELL in message or NUL_IN_FILE in message
    assert "not a safe hob id" in refused(read_only_run("hobs", "add", "--id", name, "--module", 2, "--tip-diameter",
                                                        70, "--length", 100, "--hand", "R", "--accuracy-class", "AA"))
    assert counts(read_only_run.url) == before


@pytest.mark.parametrize("name", UNSAFE["class"])
def test_template_import_refuses_an_unsafe_class(read_only_run, tmp_path, name):
    assert read_only_run("template", "export", "--class", "spur", "--out", tmp_path / "spur.csv").exit_code == 0
    before = counts(read_only_run.url)
    assert "not a safe class name" in refused(read_only_run("template", "import", "--class", name,
                                                            tmp_path / "spur.csv"))
    assert counts(read_only_run.url) == before


@pytest.mark.parametrize("name", [name for name in UNSAFE["drawing"] if "/" not in name and "\x00" not in name
                                  and name])
def test_import_dxf_refuses_an_unsafe_drawing_file_name(read_only_run, tmp_path, name):
    seed_drawing(tmp_path / name)
    before = counts(read_only_run.url)
    assert "not a safe drawing name" in refused(read_only_run("import-dxf", tmp_path / name))
    assert counts(read_only_run.url) == before


@pytest.mark.parametrize("name", UNSAFE["program"])
def test_import_dxf_refuses_an_unsafe_program_name(read_only_run, tmp_path, name):
    seed_drawing(tmp_path / "part.dxf")
    before = counts(read_only_run.url)
    assert "not a safe program name" in refused(read_only_run("import-dxf", tmp_path / "part.dxf", "--program-name",
                                                              name))
    assert counts(read_only_run.url) == before


@pytest.mark.parametrize("file_name, made", [("1part.dxf", "1PART"), ("a" * 25 + ".dxf", "A" * 25),
                                             ("p.dxf", "P"), ("part(1).dxf", None)])
def test_a_program_name_made_from_a_file_name_is_refused_not_cut(run, tmp_path, file_name, made):
    """On an 840D lathe the name is the program (on an ISO lathe it is only the comment after the
    O number: tests/test_dxf_cad_conventions.py)."""
    seed_drawing(tmp_path / file_name)
    before = counts(run.url)
    message = refused(run("import-dxf", tmp_path / file_name, "--machine", "lathe-840d"))
    assert (f"'{made}' made from its file name" in message and "--program-name" in message) if made else \
        "rename the file" in message
    assert counts(run.url) == before
    if made:
        assert run("import-dxf", tmp_path / file_name, "--machine", "lathe-840d",
                   "--program-name", "PART_1").exit_code == 0


def test_a_turning_job_s_names_are_checked_where_they_are_used():
    """Jobs stored before the database checked names are refused when made again."""
    for key, value in (("program_name", "A)B;"), ("program_name", "A" * 25), ("drawing", "x" + NEWLINE)):
        params = {"tool_change_z": 1, "tool_change_x": 1, "clearance": 1, "closed_by_axis": True,
                  "program_number": 1, "program_name": "PART", "drawing": "part.dxf", key: value}
        with pytest.raises(EngineError, match=rf"params\.{key} = .* must be"):
            check_job_params(params)


# --- the database refuses them too ---------------------------------------------------------

def refused_in_sql(conn, statement: str, values=()) -> None:
    with pytest.raises(CheckViolation):
        with conn.transaction():
            conn.execute(statement, values)


RUNNER_EDIT = "UPDATE job SET params = jsonb_set(params, %s::text[], to_jsonb(%s::text)) WHERE id = %s"


@pytest.mark.parametrize("key, kind", [("{program_name}", "program"), ("{drawing}", "drawing"),
                                       ("{machine}", "machine"), ("{gear_class}", "class"), ("{hob_id}", "hob")])
def test_a_runner_s_edit_of_a_name_in_job_params_is_refused(conn, key, kind):
    job_id = instantiate_gear(conn, 42).job_id
    conn.execute("SET ROLE engine_runner")
    for name in UNSAFE[kind]:
        if "\x00" not in name:
            refused_in_sql(conn, RUNNER_EDIT, (key, name, job_id))
    refused_in_sql(conn, RUNNER_EDIT, ("{hand}", "R" + NEWLINE, job_id))    # any text of a job: no line break
    refused_in_sql(conn, "UPDATE job SET module_params = jsonb_set(module_params, '{cutmotion:1,cut_name}', "
                         "to_jsonb(%s::text)) WHERE id = %s", ("rough" + NEWLINE, job_id))
    conn.execute(RUNNER_EDIT, ("{program_name}", "GEAR_42_B", job_id))     # a safe name is taken
    conn.execute("RESET ROLE")


def test_names_written_in_sql_are_refused(conn):
    for name in UNSAFE["hob"]:
        if "\x00" not in name:
            refused_in_sql(conn, "INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class) "
                                 "VALUES (%s, 2, 1, 70, 100, 'R', 'AA')", (name,))
    for name in UNSAFE["class"]:
        if "\x00" not in name:
            refused_in_sql(conn, "INSERT INTO gear_class (name) VALUES (%s)", (name,))
    for name in UNSAFE["machine"]:
        if "\x00" not in name:
            refused_in_sql(conn, "INSERT INTO machine (name, kind, dialect, x_min, x_max, z_min, z_max, spindle_max) "
                                 "VALUES (%s, 'lathe', 'iso', 0, 1, 0, 1, 1)", (name,))


def test_a_program_with_an_unsafe_name_or_a_broken_line_is_refused_in_sql(conn):
    program = instantiate_gear(conn, 42)
    insert = ("INSERT INTO program (job_id, gear_class, template_version, template_hash, name, lines, row_ids) "
              # the version and hash it was made from: only the name or line is wrong
              "VALUES (%s, 'spur', %s, %s, %s, %s, %s)")
    made_from = (program.template_version, program.template_hash)
    for name in UNSAFE["program"]:
        if "\x00" not in name:
            refused_in_sql(conn, insert, (program.job_id, *made_from, name, ["M30"], [program.row_ids[-1]]))
    for line in ("; A" + NEWLINE, "; A\rG0 X9999", "; A\u2028G0", "; A\x0bB", "; A\x85B"):
        refused_in_sql(conn, insert, (program.job_id, *made_from, "GEAR42", [line, "M30"], program.row_ids[-2:]))


def test_the_migration_names_rows_written_before_it_and_stops(empty_database_url, tmp_path):
    before = tmp_path / "before"
    before.mkdir()
    for path in sorted(MIGRATIONS_DIR.glob("*.sql")):
        if path.name < "0009":
            shutil.copy(path, before / path.name)
    with psycopg.connect(empty_database_url) as conn:
        migrate(conn, before)
        conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class) "
                     "VALUES (%s, 2, 1, 70, 100, 'R', 'AA')", ("H1" + NEWLINE,))
        conn.execute("INSERT INTO gear_class (name) VALUES ('spur')")
        conn.execute("INSERT INTO machine (name, kind, dialect, x_min, x_max, z_min, z_max, spindle_max) "
                     "VALUES ('hobber-840d', 'hobber', '840d', 0, 1, 0, 1, 1)")
        job_id = conn.execute("INSERT INTO job (gear_class, machine, params) VALUES ('spur', 'hobber-840d', "
                              "'{\"program_name\": \"../../x\"}') RETURNING id").fetchone()[0]
        conn.commit()
        with pytest.raises(EngineError) as failure:
            migrate(conn, MIGRATIONS_DIR)
        message = str(failure.value)
        assert "0009.safe_names.sql" in message and r'hob "H1\nG0 X9999 Z-9999"' in message
        assert f'job {job_id} params.program_name = "../../x"' in message
        conn.rollback()
        assert conn.execute("SELECT max(version) FROM schema_migration").fetchone()[0] < "0009"


# --- a line break through any route never reaches a stored program or a file ---------------------

def injected_anywhere(url, folder) -> list[str]:
    with psycopg.connect(url) as conn:
        lines = [line for (lines,) in conn.execute("SELECT lines FROM program") for line in lines]
    texts = lines + [path.read_text() for path in folder.rglob("*") if path.is_file()]
    return [text for text in texts if "X9999" in text]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_no_route_puts_a_block_into_a_program(run, tmp_path):
    out = tmp_path / "out"
    assert run("instantiate", "--gears", "42-43", "--out", out, "--mkdir").exit_code == 0
    with psycopg.connect(run.url) as conn:   # 1. a runner's edit of job.params
        job_id = conn.execute("SELECT max(id) FROM job").fetchone()[0]
        for name in ("GEAR43" + NEWLINE, "../../x"):
            conn.execute("SET ROLE engine_runner")
            with pytest.raises(CheckViolation):
                conn.execute(RUNNER_EDIT, ("{program_name}", name, job_id))
            conn.rollback()
    assert run("instantiate", "--job", job_id, "--out", out / "again").exit_code == 0
    seed_drawing(tmp_path / ("part" + NEWLINE + ".dxf"))   # 2. a drawing's file name
    refused(run("import-dxf", tmp_path / ("part" + NEWLINE + ".dxf")))
    write_csv(tmp_path / "hobs.csv", HOB_HEADER, ["H-M2-AA-R1" + NEWLINE, "2", "20", "1", "70", "100", "R", "AA",
                                                 "HSS", "TiN", "cylindrical"])
    refused(run("hobs", "import", tmp_path / "hobs.csv"))   # 3. a hob id
    assert run("instantiate", "--all", "--out", out / "all", "--mkdir").exit_code == 0
    before = counts(run.url)
    for breaking in ("\\n", "\\r", "\\u2028"):   # 4. a template row's output (its text holds the escape)
        with psycopg.connect(run.url) as conn:
            conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = 300",
                         (f'"; GEAR{breaking}{INJECTED}"',))
        refused(run("instantiate", "--gear", 42, "--draft"))   # the editor tries it (a draft: no file)
    assert counts(run.url) == before and not (out / "row").exists()
    assert injected_anywhere(run.url, out) == []
