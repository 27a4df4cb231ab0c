"""Release control as the shop floor relies on it (issue 15): an edit through template_view goes
into the class's draft and changes nothing runners get until it is released; only an editor makes
a draft's program; a parent's release leaves its children's released rows alone; and every program
carries its lineage line, which the database checks and `engine programs show --hash` finds."""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import psycopg
import pytest
from helpers.drawings import DXF, EMCO, seed_drawing
from helpers.lineage_text import id_masked
from helpers.releases import release_draft
from helpers.roles import as_role
from psycopg import errors, sql
from psycopg.types.json import Jsonb

from engine.errors import EngineError
from engine.nc.lineage import LINEAGE_ROW_ID
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.simulation import simulate_stored_program

SEEDED_GEARS = (42, 43, 44, 45, 46, 47, 50, 51, 53, 54)   # seed_templates/gears.csv: every hobbing class
BROKEN_EDIT = "UPDATE template_view SET o = 'M8 ; COOLANT ON' WHERE gear_class = 'spur' AND o = '\"M8\"'"
# A valid edit that still parses and changes a number on the machine: the radial feed of the cut halved.
FEED_EDIT = ("UPDATE template_view SET o = 'f\"G1 X{cut_x:.3f} F{feed_radial * 0.5:.1f}\"' "
             "WHERE gear_class = 'spur' AND id = 2600")
RADIAL_FEED = re.compile(r"G1 X[0-9.]+ F([0-9.]+)$")
LINEAGE = re.compile(r"^(?:; (?P<semicolon>.*)|\((?P<iso>.*)\))$")


def runner_lines(conn, gear_id: int) -> list[str]:
    """The program a runner (role engine_runner) makes of the gear, its program id masked."""
    with as_role(conn, "engine_runner"):
        return id_masked(instantiate_gear(conn, gear_id).lines)


def radial_feed(lines: list[str]) -> float:
    return float(next(RADIAL_FEED.fullmatch(line).group(1) for line in lines if RADIAL_FEED.fullmatch(line)))


def states(conn, gear_class: str) -> dict[int, str]:
    return dict(conn.execute("SELECT version, state FROM template_version_state WHERE gear_class = %s",
                             (gear_class,)).fetchall())


def has_draft(conn, gear_class: str) -> bool:
    """The class's current rows are not its released version (a version is stored at COMMIT, or
    when a program is made of it: template_version_state lists it only then)."""
    return conn.execute("SELECT template_version IS DISTINCT FROM released_version(name) FROM gear_class "
                        "WHERE name = %s", (gear_class,)).fetchone()[0]


def current_version(conn, gear_class: str) -> int:
    return conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (gear_class,)).fetchone()[0]


# --- an edit goes into the draft -----------------------------------------------------------------------

def test_a_broken_edit_through_the_view_does_not_reach_runners(conn):
    released, duplex = runner_lines(conn, 42), runner_lines(conn, 54)
    with as_role(conn, "engine_editor"):
        assert conn.execute(BROKEN_EDIT).rowcount == 1   # psql says UPDATE 1, as the issue found
    assert runner_lines(conn, 42) == released
    assert runner_lines(conn, 54) == duplex   # duplex inherits the row: its runners keep theirs too
    with pytest.raises(EngineError, match="class spur row 1800 column o"):
        instantiate_gear(conn, 42, mode=RunMode(draft=True))   # only the editor trying the draft meets it


def test_a_valid_edit_of_a_number_is_the_drafts_only(conn):
    released = runner_lines(conn, 42)
    with as_role(conn, "engine_editor"):
        conn.execute(FEED_EDIT)
    assert runner_lines(conn, 42) == released
    draft = instantiate_gear(conn, 42, mode=RunMode(draft=True))
    # both printed to 0.1: the half is off by 0.05 at most, half the released one by 0.025
    assert abs(radial_feed(draft.lines) - radial_feed(released) / 2) <= 0.075 + 1e-9
    assert draft.template_version == current_version(conn, "spur") and states(conn, "spur")[draft.template_version] \
        == "draft"


def test_the_cli_gives_runners_the_released_lines_and_the_editor_the_draft(run):
    released = run("instantiate", "--gear", 42)
    with psycopg.connect(run.url) as conn:
        conn.execute(FEED_EDIT)
    again, draft = run("instantiate", "--gear", 42), run("instantiate", "--gear", 42, "--draft")
    assert released.exit_code == again.exit_code == draft.exit_code == 0, draft.output
    assert id_masked(again.stdout.splitlines()) == id_masked(released.stdout.splitlines())
    assert radial_feed(draft.stdout.splitlines()) < radial_feed(released.stdout.splitlines())
    assert re.search(r"^; PROGRAM \d+ TEMPLATE spur v\d+ [0-9a-f]{8} INPUT [0-9a-f]{8} DRAFT$", draft.stdout, re.M)
    with psycopg.connect(run.url) as conn:
        conn.execute(BROKEN_EDIT)
    assert run("instantiate", "--gear", 42).exit_code == 0
    refused = run("instantiate", "--gear", 42, "--draft")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1 and "row 1800" in refused.stderr


# --- release ------------------------------------------------------------------------------------------

def test_after_release_runners_get_the_new_version_and_the_old_one_is_retired(conn):
    old = current_version(conn, "spur")
    released = runner_lines(conn, 42)
    with as_role(conn, "engine_editor"):
        conn.execute(FEED_EDIT)
    new = current_version(conn, "spur")
    release_draft(conn, "spur")
    with as_role(conn, "engine_runner"):
        program = instantiate_gear(conn, 42)
    assert program.template_version == new and radial_feed(program.lines) < radial_feed(released)
    assert states(conn, "spur")[old] == "retired" and states(conn, "spur")[new] == "released"
    assert conn.execute("SELECT draft FROM program WHERE id = %s", (program.program_id,)).fetchone() == (False,)


# --- only an editor makes a draft's program --------------------------------------------------------------

def test_a_runner_cannot_store_a_draft_program_an_editor_who_runs_can(conn):
    conn.execute(FEED_EDIT)
    with pytest.raises(errors.InsufficientPrivilege, match="only an editor"), conn.transaction(), \
            as_role(conn, "engine_runner"):
        instantiate_gear(conn, 42, mode=RunMode(draft=True))
    both = "release_runtime_editor_runner"
    conn.execute(sql.SQL("CREATE ROLE {} NOLOGIN IN ROLE engine_editor, engine_runner").format(sql.Identifier(both)))
    with as_role(conn, both):
        program = instantiate_gear(conn, 42, mode=RunMode(draft=True))
    draft, stored_role = conn.execute("SELECT draft, stored_role FROM program WHERE id = %s",
                                      (program.program_id,)).fetchone()
    lineage = [line for line, row in zip(program.lines, program.row_ids) if row == LINEAGE_ROW_ID]
    assert draft is True and stored_role == both and len(lineage) == 1 and lineage[0].endswith(" DRAFT")


# --- a parent's release and its children ---------------------------------------------------------------

def released_rows(conn, gear_class: str) -> list[tuple]:
    return conn.execute("SELECT version, id, t, n, p_calc, s, o, p_emit FROM released_template_view "
                        "WHERE gear_class = %s ORDER BY id", (gear_class,)).fetchall()


def test_a_parents_release_leaves_the_childrens_released_rows_alone(conn):
    duplex_before, duplex_lines = released_rows(conn, "duplex"), runner_lines(conn, 54)
    with as_role(conn, "engine_editor"):
        conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; SPUR EDIT\"' "
                     "WHERE gear_class = 'spur' AND id = 800")
    assert has_draft(conn, "spur") and has_draft(conn, "duplex")
    release_draft(conn, "spur")
    assert released_rows(conn, "duplex") == duplex_before
    assert runner_lines(conn, 54) == duplex_lines and "G90 G71 G94 ; SPUR EDIT" not in duplex_lines
    assert "G90 G71 G94 ; SPUR EDIT" in runner_lines(conn, 42)
    assert has_draft(conn, "duplex") and not has_draft(conn, "spur")
    assert "G90 G71 G94 ; SPUR EDIT" in instantiate_gear(conn, 54, mode=RunMode(draft=True)).lines


# --- every program carries its lineage -----------------------------------------------------------------

def expected_lineage(conn, program_id: int) -> str:
    """The line from the program's record and its job's parameters; INPUT is the sha256 of the
    parameters as the database writes them (jsonb's text of [params, module_params]), computed
    here and held to the database's own job_input_hash."""
    gear_class, version, template_hash, draft, params_text, database_hash = conn.execute(
        "SELECT p.gear_class, p.template_version, p.template_hash, p.draft, "
        "jsonb_build_array(coalesce(j.params, '{}'), coalesce(j.module_params, '{}'))::text, "
        "job_input_hash(j.params, j.module_params) FROM program p JOIN job j ON j.id = p.job_id WHERE p.id = %s",
        (program_id,)).fetchone()
    input_hash = hashlib.sha256(params_text.encode("utf-8")).hexdigest()
    assert database_hash == input_hash[:16]
    words = f"PROGRAM {program_id} TEMPLATE {gear_class} v{version} {template_hash[:8]} INPUT {input_hash[:8]}"
    return words + (" DRAFT" if draft else "")


def check_lineage(run, program_id: int, path: Path) -> None:
    """The stored program's one lineage line is the expected one, in the header after the
    template's version line; the file written is the stored program; --hash finds it."""
    with psycopg.connect(run.url) as conn:
        lines, row_ids = conn.execute("SELECT lines, row_ids FROM program WHERE id = %s", (program_id,)).fetchone()
        words = expected_lineage(conn, program_id)
    at = row_ids.index(LINEAGE_ROW_ID)
    assert row_ids.count(LINEAGE_ROW_ID) == 1 and lines[at] in (f"; {words}", f"({words})")
    assert re.match(r"[;(] ?TEMPLATE ", lines[at - 1], re.IGNORECASE), lines[at - 1]
    assert path.read_text() == "\n".join(lines) + "\n"
    found = run("programs", "show", "--hash", words.split(" INPUT ")[1][:8], "--json")
    assert found.exit_code == 0 and found.stdout.count("\n") == 1
    assert program_id in [record["program_id"] for record in json.loads(found.stdout)["programs"]]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_every_seeded_gears_program_carries_its_lineage(run, tmp_path):
    for gear_id in SEEDED_GEARS:
        made = run("instantiate", "--gear", gear_id, "--out", tmp_path / f"G{gear_id}.MPF", "--json")
        assert made.exit_code == 0, made.output
        check_lineage(run, json.loads(made.stdout)["program_id"], tmp_path / f"G{gear_id}.MPF")


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("machine, drawing", [("lathe-iso", "emco"), ("lathe-840d", "seed")])
def test_a_turning_jobs_program_carries_its_lineage(run, tmp_path, machine, drawing):
    path = DXF / EMCO[0] if drawing == "emco" else tmp_path / "part.dxf"
    if drawing == "seed":
        seed_drawing(path)
    options = ("--rough-depth", "1", "--program-name", "EMCO_NEG") if drawing == "emco" else ()
    imported = run("import-dxf", path, "--machine", machine, *options, "--json")
    assert imported.exit_code == 0, imported.output
    made = run("instantiate", "--job", json.loads(imported.stdout)["job_id"], "--out", tmp_path / "P.NC", "--json")
    assert made.exit_code == 0, made.output
    program_id = json.loads(made.stdout)["program_id"]
    check_lineage(run, program_id, tmp_path / "P.NC")
    assert json.loads(imported.stdout)["program_lines"] == len((tmp_path / "P.NC").read_text().splitlines())


def batch_programs(run, folder: Path, *args) -> list[tuple[int, Path]]:
    made = run("instantiate", *args, "--out", folder, "--mkdir", "--json")
    assert made.exit_code == 0, made.output
    report = json.loads(made.stdout)
    with psycopg.connect(run.url) as conn:
        named = conn.execute("SELECT id, name FROM program WHERE id BETWEEN %s AND %s ORDER BY id",
                             report["program_ids"]).fetchall()
    return [(program_id, folder / f"{name}.MPF") for program_id, name in named]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_batches_and_remade_jobs_carry_their_lineage(run, tmp_path):
    batch = batch_programs(run, tmp_path / "batch", "--gears", "42-54")
    with psycopg.connect(run.url) as conn:
        jobs = [row[0] for row in conn.execute("SELECT job_id FROM program WHERE id = ANY(%s) ORDER BY job_id",
                                               ([program_id for program_id, _ in batch],))]
    remade = batch_programs(run, tmp_path / "remade", "--jobs", f"{jobs[0]}-{jobs[-1]}")
    assert len(batch) == len(remade) == len(SEEDED_GEARS)
    for program_id, path in batch + remade:
        check_lineage(run, program_id, path)
    one = run("instantiate", "--job", jobs[0], "--out", tmp_path / "ONE.MPF", "--json")
    assert one.exit_code == 0, one.output
    check_lineage(run, json.loads(one.stdout)["program_id"], tmp_path / "ONE.MPF")


def test_a_stored_program_whose_class_name_holds_a_header_word_simulates(conn):
    """`gear_hobbed` holds GEAR and HOB: its lineage line is still no header claim."""
    conn.execute("INSERT INTO gear_class (name, parent) VALUES ('gear_hobbed', 'spur')")
    conn.execute("""INSERT INTO gear SELECT (jsonb_populate_record(NULL::gear, to_jsonb(g) ||
                    '{"id": 9042, "gear_class": "gear_hobbed"}')).* FROM gear g WHERE g.id = 42""")
    release_draft(conn, "gear_hobbed")
    program = instantiate_gear(conn, 9042)
    assert any(" TEMPLATE gear_hobbed v" in line for line in program.lines)
    report = simulate_stored_program(conn, program.program_id)
    assert not report.refused, "\n".join(report.lines())


# --- the database refuses a lineage line it did not expect -----------------------------------------------

SUBMIT = ("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, "
          "row_ids, trace) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s)")
FORGED_LINEAGE = {   # what is forged → the lineage line's new text (None: left out)
    "missing": lambda line, program_id: None,
    "another program's id": lambda line, program_id: re.sub(r"PROGRAM \d+", f"PROGRAM {program_id - 1}", line),
    "wrong input hash": lambda line, program_id: re.sub(r"INPUT [0-9a-f]{8}", "INPUT 00000000", line),
    "wrong version": lambda line, program_id: re.sub(r" v(\d+) ", lambda m: f" v{int(m[1]) + 1} ", line),
    "a released program claiming DRAFT": lambda line, program_id: line + " DRAFT",
    "parentheses inside a comment": lambda line, program_id: f"; ({line[2:]})",
}


def submit_again(conn, program, lineage_of) -> None:
    """Submit the program again under a new id as superuser, its lineage line made by
    lineage_of(the right line, new id) (None: left out)."""
    program_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    right = f"; {expected_lineage(conn, program.program_id)}".replace(f"PROGRAM {program.program_id} ",
                                                                        f"PROGRAM {program_id} ")
    line = lineage_of(right, program_id)
    kept = [(line if row == LINEAGE_ROW_ID else text, row) for text, row in zip(program.lines, program.row_ids)
            if row != LINEAGE_ROW_ID or line is not None]
    conn.execute(SUBMIT, (program_id, program.job_id, "spur", program.template_version, program.template_hash,
                          program.name, [text for text, _ in kept], [row for _, row in kept], Jsonb(program.trace)))


@pytest.mark.parametrize("forgery", FORGED_LINEAGE, ids=list(FORGED_LINEAGE))
def test_the_database_refuses_a_wrong_or_missing_lineage_line(conn, forgery):
    program = instantiate_gear(conn, 42)
    submit_again(conn, program, lambda right, program_id: right)   # the right line passes
    with pytest.raises(errors.CheckViolation, match="lineage line"), conn.transaction():
        submit_again(conn, program, FORGED_LINEAGE[forgery])


# --- a class an import made has no release ---------------------------------------------------------------

def test_a_class_made_by_import_nc_runs_only_as_a_draft_until_released(run, tmp_path):
    (tmp_path / "part.mpf").write_text("%_N_NC_PART_MPF\n;$PATH=/_N_MPF_DIR\nG90 G71 G94\nM30\n")
    imported = run("import-nc", tmp_path / "part.mpf", "--class", "nc_part")
    assert imported.exit_code == 0, imported.output
    assert "is a draft" in imported.stderr and "--draft" in imported.stderr
    assert "engine template release --class nc_part" in imported.stderr
    with psycopg.connect(run.url) as conn:
        job = conn.execute("INSERT INTO job (gear_class, machine, params) VALUES ('nc_part', 'hobber-840d', "
                           "'{\"program_name\": \"NC_PART\"}') RETURNING id").fetchone()[0]
    refused = run("instantiate", "--job", job)
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert "class 'nc_part' has no released template version" in refused.stderr and "--draft" in refused.stderr


# --- engine programs show ------------------------------------------------------------------------------

@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_programs_show_gives_the_record_and_refuses_in_one_line(run):
    made = json.loads(run("instantiate", "--gear", 42, "--json").stdout)
    shown = run("programs", "show", made["program_id"], "--json")
    assert shown.exit_code == 0 and shown.stdout.count("\n") == 1
    record = json.loads(shown.stdout)["programs"][0]
    assert (record["program_id"], record["job_id"], record["gear_id"], record["class"], record["draft"]) == \
        (made["program_id"], made["job_id"], 42, "spur", False)
    assert record["template_version"] == made["template_version"] and len(record["lines"]) == made["lines"]
    text = run("programs", "show", made["program_id"])
    assert text.exit_code == 0 and f"; PROGRAM {made['program_id']} TEMPLATE spur" in text.stdout
    for args, words in ((("999999",), "program 999999 does not exist"), (("--hash", "12ab"), "8 or more hex"),
                        (("--hash", "ffffffffffff"), "no program has"), ((), "one of the two")):
        refused = run("programs", "show", *args)
        assert refused.exit_code == 1 and refused.stderr.count("\n") == 1 and words in refused.stderr, refused.stderr


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_role_without_the_right_gets_one_line_and_exit_1(fresh_database_url):
    """An editor alone (no engine_runner) trying a draft, or a reader instantiating: the database
    refuses; the user reads which roles may do it, exit 1, and nothing is stored."""
    import os
    import subprocess
    import sys

    import psycopg

    for role, args in (("engine_editor", ["--draft"]), ("engine_reader", [])):
        environment = dict(os.environ, DATABASE_URL=fresh_database_url, PGOPTIONS=f"-c role={role}")
        done = subprocess.run([sys.executable, "-m", "engine", "instantiate", "--gear", "42", *args],
                              capture_output=True, text=True, env=environment)
        assert done.returncode == 1, done.stderr
        assert done.stderr.count("\n") == 1 and "engine_runner makes programs" in done.stderr
    with psycopg.connect(fresh_database_url) as conn:
        assert conn.execute("SELECT count(*) FROM job").fetchone()[0] == 0
