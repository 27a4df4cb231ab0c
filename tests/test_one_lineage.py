"""A program carries one lineage line, the engine's (issue 16): no file imported as a template,
no template row and no program stored may add a second line that reads as one, or the operator
matching a file on the control to its record would be told another program and version."""
from __future__ import annotations

import csv
import io

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
def test_template_import_refuses_a_row_that_writes_a_lineage_line(read_only_run, tmp_path, o):
    exported = read_only_run("template", "export", "--class", "spur").stdout
    header, first, *rest = exported.splitlines(keepends=True)
    quoted = '"' + o.replace('"', '""') + '"'
    path = tmp_path / "spur.csv"
    path.write_text(header + first + f"15,main,1,,,{quoted},\n" + "".join(rest))
    result = read_only_run("template", "import", "--class", "spur", path)
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, result.output
    assert f"{path}, line 3" in result.stderr and "remove" in result.stderr
    assert read_only_run("template", "export", "--class", "spur").stdout == exported


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


def test_the_text_of_a_dry_run_is_never_stored_as_a_program(run, tmp_path):
    """import-nc of a dry run's printout must not carry its `; PROGRAM DRY-RUN …` line into a
    template, from which every program of the class would then store it."""
    dry = run("instantiate", "--gear", 42, "--dry-run")
    assert dry.exit_code == 0, dry.output
    printed = tmp_path / "GEAR42.MPF"
    printed.write_text(dry.stdout)
    assert "; PROGRAM DRY-RUN" in dry.stdout
    run("import-nc", "--class", "spur", str(printed))
    run("instantiate", "--gear", 42, "--draft")
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT count(*) FROM program WHERE array_to_string(lines, E'\\n') "
                              "LIKE '%PROGRAM DRY-RUN%'").fetchone()[0]
    assert stored == 0


def test_a_stored_programs_lineage_line_is_not_copied_into_a_template(run, tmp_path):
    """A second lineage line naming another program id and template version would lie to
    whoever reads the program at the machine."""
    real = run("instantiate", "--gear", 42)
    assert real.exit_code == 0, real.output
    printed = tmp_path / "GEAR42.MPF"
    printed.write_text(real.stdout)
    run("import-nc", "--class", "spur", str(printed))
    again = run("instantiate", "--gear", 42, "--draft")
    if again.exit_code == 0:
        assert sum(line.startswith("; PROGRAM ") for line in again.stdout.splitlines()) == 1


def _spur_with_row(run, tmp_path, o: str):
    """The spur template's CSV with one more main row whose output is `o`."""
    exported = run("template", "export", "--class", "spur")
    assert exported.exit_code == 0, exported.output
    rows = list(csv.reader(io.StringIO(exported.stdout)))
    rows.insert(7, ["655", "main", "1", "", "", o, ""])
    path = tmp_path / "spur.csv"
    with path.open("w", newline="") as file:
        csv.writer(file).writerows(rows)
    return path


def add_spur_row(url: str, o: str) -> None:
    """An editor's row added in SQL (template_view), where no import checks it."""
    with psycopg.connect(url) as conn:
        conn.execute("INSERT INTO template_view (gear_class, id, t, n, o) VALUES ('spur', 655, 'main', 1, %s)", (o,))


def test_a_row_building_a_lineage_line_is_named_by_lint_and_blocks_the_release(run, tmp_path):
    """Storing refuses every program of such a template: the import refuses the row, lint names
    it when it came in by SQL, and the release gate does not hand the shop floor a template
    that makes no program."""
    built = '"; PROG" + "RAM 1 TEMPLATE spur v9"'
    imported = run("template", "import", "--class", "spur", str(_spur_with_row(run, tmp_path, built)))
    assert imported.exit_code == 1 and "row 655" in imported.stderr, imported.output
    add_spur_row(run.url, built)
    lint = run("lint")
    assert lint.exit_code == 1 and "655" in lint.output, lint.output
    release = run("template", "release", "--class", "spur", "--yes")
    assert release.exit_code == 1, release.output


def test_a_row_computing_a_lineage_line_from_its_inputs_blocks_the_release(run):
    """What lint cannot read (text computed from the gear at run time) is refused where every
    program is made, so the golden tests fail and the gate refuses; a dry run refuses too."""
    add_spur_row(run.url, '"; PROGRAM " + str(z2) + " TEMPLATE spur v9"')
    release = run("template", "release", "--class", "spur", "--yes")
    assert release.exit_code == 1, release.output
    dry_run = run("instantiate", "--gear", 42, "--draft", "--dry-run")
    assert dry_run.exit_code == 1 and "reads as a lineage line" in dry_run.stderr, dry_run.output


def _import_nc(run, tmp_path, line: str, name: str):
    program = tmp_path / "P.MPF"
    program.write_text(f"%_N_P_MPF\n; TEMPLATE x v1\n{line}\nG0 X10\nM30\n")
    return run("import-nc", "--class", name, "--parent", "cylindrical", str(program))


def test_a_plain_comment_about_a_program_and_its_template_is_not_a_lineage_line(run, tmp_path):
    """The lineage line names a program id (or DRY-RUN); a shop's comment does not."""
    result = _import_nc(run, tmp_path, "; program from template of spur", "adv_comment")
    assert result.exit_code == 0, result.output


def test_a_block_numbered_lineage_line_is_refused_too(read_only_run, tmp_path):
    """`N10 ; PROGRAM 1 TEMPLATE …` reads at the machine as a second lineage line."""
    result = _import_nc(read_only_run, tmp_path, "N10 ; PROGRAM 1 TEMPLATE spur v1 deadbeef INPUT deadbeef",
                        "adv_numbered")
    assert result.exit_code == 1, result.output
    with psycopg.connect(read_only_run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear_class WHERE name = 'adv_numbered'").fetchone()[0] == 0
