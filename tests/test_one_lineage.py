"""A program carries one lineage line, the engine's (issue 16): no file imported as a template,
no template row and no program stored may add a second line that reads as one, or the operator
matching a file on the control to its record would be told another program and version."""
from __future__ import annotations

import psycopg
import pytest
from psycopg import errors
from psycopg.types.json import Jsonb

from engine.nc.lineage import LINEAGE_ROW_ID
from engine.programs.instantiate import instantiate_gear

SUBMIT = ("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, "
          "row_ids, trace) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s)")
LINEAGE_SHAPED = (   # as the engine writes it (840D, ISO, a dry run's, a draft's) and as a hand copies it
    "; PROGRAM 812 TEMPLATE spur v3 0123abcd INPUT 4567cdef",
    "; PROGRAM DRY-RUN TEMPLATE spur v3 0123abcd INPUT 4567cdef DRAFT",
    "(PROGRAM 812 TEMPLATE spur v3 0123abcd INPUT 4567cdef)",
    "  ;program 812 template spur",
    "G0 X10 ; PROGRAM 812 TEMPLATE spur",   # after a move it reads the same at the control
    "N10 ; PROGRAM 812 TEMPLATE spur",
)
NOT_LINEAGE = ("; PROGRAM START", "; TEMPLATE spur v3", "; program from template of spur")


def template_version(url: str, gear_class: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (gear_class,)).fetchone()[0]


def submit_with_line(conn, text: str) -> None:
    """Gear 42's program submitted again, its first template-written comment line replaced by `text`."""
    program = instantiate_gear(conn, 42)
    at = next(number for number, (line, row) in enumerate(zip(program.lines, program.row_ids))
              if row != LINEAGE_ROW_ID and line.lstrip().startswith(";"))
    lines = program.lines[:at] + [text] + program.lines[at + 1:]
    program_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    lineage = [line.replace(f"PROGRAM {program.program_id} ", f"PROGRAM {program_id} ") for line in lines]
    conn.execute(SUBMIT, (program_id, program.job_id, program.gear_class, program.template_version,
                          program.template_hash, program.name, lineage, program.row_ids, Jsonb(program.trace)))


@pytest.mark.parametrize("text", LINEAGE_SHAPED)
def test_the_database_refuses_a_template_line_that_reads_as_a_lineage_line(conn, text):
    with pytest.raises(errors.CheckViolation, match="reads as a lineage line"), conn.transaction():
        submit_with_line(conn, text)


@pytest.mark.parametrize("text", NOT_LINEAGE)
def test_the_database_keeps_comments_that_only_mention_a_program(conn, text):
    with conn.transaction():
        submit_with_line(conn, text)


@pytest.mark.parametrize("copied", ["stored", "dry run"])
def test_import_nc_refuses_a_printed_program_naming_the_file_and_line(run, tmp_path, copied):
    printed = run("instantiate", "--gear", 42, *(["--dry-run"] if copied == "dry run" else []))
    assert printed.exit_code == 0, printed.output
    number = next(n for n, line in enumerate(printed.stdout.splitlines(), 1) if line.startswith("; PROGRAM "))
    path = tmp_path / "GEAR42.MPF"
    path.write_text(printed.stdout)
    before = template_version(run.url, "spur")
    result = run("import-nc", "--class", "spur", path)
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, result.output
    assert str(path) in result.stderr and f"line {number} " in result.stderr and "remove" in result.stderr
    assert template_version(run.url, "spur") == before


@pytest.mark.parametrize("o", ['"; PROGRAM 812 TEMPLATE spur v3 0123abcd INPUT 4567cdef"',
                               "f\"(PROGRAM {program_name} TEMPLATE spur v3 0123abcd INPUT 4567cdef)\""])
def test_template_import_refuses_a_row_that_writes_a_lineage_line(run, tmp_path, o):
    exported = run("template", "export", "--class", "spur").stdout
    header, first, *rest = exported.splitlines(keepends=True)
    quoted = '"' + o.replace('"', '""') + '"'
    path = tmp_path / "spur.csv"
    path.write_text(header + first + f"15,main,1,,,{quoted},\n" + "".join(rest))
    result = run("template", "import", "--class", "spur", path)
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, result.output
    assert f"{path}, line 3" in result.stderr and "remove" in result.stderr
    assert run("template", "export", "--class", "spur").stdout == exported


def test_a_row_edited_in_sql_to_write_a_lineage_line_is_named_by_lint_and_stores_nothing(run):
    with psycopg.connect(run.url) as conn:
        row_id = conn.execute("SELECT min(id) FROM template_view WHERE gear_class = 'spur' AND o LIKE '\";%'"
                              ).fetchone()[0]
        conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = %s",
                     ('"; PROGRAM 7 TEMPLATE spur v1 0123abcd INPUT 4567cdef"', row_id))
        programs = conn.execute("SELECT count(*) FROM program").fetchone()[0]
    linted = run("lint")
    assert linted.exit_code == 1 and f"class spur row {row_id} column o: " in linted.stdout
    made = run("instantiate", "--gear", 42, "--draft")
    assert made.exit_code == 1 and made.stderr.count("\n") == 1, made.output
    assert "GEAR42" in made.stderr and "lineage line" in made.stderr
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == programs
