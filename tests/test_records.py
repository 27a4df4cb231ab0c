"""Programs are records (issue 13, design notes §10): only the engine's path stores a program,
the database checks what it can of it and records who stored it, no role (the owner included)
changes or deletes one, and runners add to the machining history only what a job the engine made
vouches for, within the machine's limits and physically plausible. Templates and the audit:
test_records_templates.py."""
from __future__ import annotations

import math
import re

import psycopg
import pytest
from helpers.roles import as_role, logins
from psycopg import errors
from psycopg.types.json import Jsonb

from engine.errors import EngineError
from engine.gears.cases import confirm_job
from engine.programs.instantiate import instantiate_gear, instantiate_gears
from engine.programs.options import RunMode

# The engine's path for one program (engine.programs.storage): an id drawn from the sequence first,
# so that the program's lineage line can name it.
SUBMIT = ("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, "
          "row_ids, trace) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s) RETURNING id")


@pytest.fixture
def login_in(server_url):
    with logins(server_url) as create:
        yield create


def stored(conn, program_id):
    return conn.execute("SELECT job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace "
                        "FROM program WHERE id = %s", (program_id,)).fetchone()


def submitted(conn, values) -> int:
    """Store a program's values (job_id, …, lines, row_ids, trace) as a new program through the engine's
    path, its lineage line (row id -1) naming the new id as the engine writes it; → its id."""
    program_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    return conn.execute(SUBMIT, (program_id, *values[:5], renamed(values[5], values[6], program_id), values[6],
                                 Jsonb(values[7]))).fetchone()[0]


def renamed(lines, row_ids, program_id):
    """The lines with the lineage line's program id replaced by `program_id`."""
    return [re.sub(r"PROGRAM \d+", f"PROGRAM {program_id}", line, count=1) if row_id == -1 else line
            for line, row_id in zip(lines, row_ids)]


def program_count(conn):
    return conn.execute("SELECT count(*) FROM program").fetchone()[0]


def stored_version_hash(conn, gear_class, version):
    return conn.execute("SELECT hash FROM template_version_rows WHERE gear_class = %s AND version = %s",
                        (gear_class, version)).fetchone()[0]


@pytest.fixture
def program(conn):
    """Gear 42's program, stored by the engine in the test's transaction."""
    return instantiate_gear(conn, 42)


# --- nobody changes a program -------------------------------------------------------------------

CHANGES = [
    "UPDATE program SET lines[5] = 'G0 X9999 Z-9999' WHERE id = %(id)s",
    "UPDATE program SET template_version = template_version + 1 WHERE id = %(id)s",
    "UPDATE program SET template_hash = '0123456789abcdef' WHERE id = %(id)s",
    "DELETE FROM program WHERE id = %(id)s",
]


@pytest.mark.parametrize("statement", CHANGES, ids=["lines", "version", "hash", "delete"])
def test_a_runner_cannot_change_or_delete_a_program(conn, program, statement):
    before = stored(conn, program.program_id)
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_runner"):
        conn.execute(statement, {"id": program.program_id})
    assert stored(conn, program.program_id) == before


@pytest.mark.parametrize("statement", [*CHANGES, "DELETE FROM job WHERE id = (SELECT job_id FROM program "
                                                  "WHERE id = %(id)s)", "TRUNCATE program CASCADE"],
                         ids=["lines", "version", "hash", "delete", "its job deleted", "truncate"])
def test_not_even_the_owner_changes_or_deletes_a_program(conn, program, statement):
    before = stored(conn, program.program_id)
    with pytest.raises(errors.InsufficientPrivilege, match="records, never changed or deleted"), \
            conn.transaction():
        conn.execute(statement, {"id": program.program_id})
    assert stored(conn, program.program_id) == before


def test_a_runner_cannot_write_the_program_table_at_all(conn, program):
    forged = stored(conn, program.program_id)
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_runner"):
        conn.execute("INSERT INTO program (job_id, gear_class, template_version, template_hash, name, lines, "
                     "row_ids) VALUES (%s, %s, %s, %s, %s, %s, %s)", forged[:7])
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_runner"):
        with conn.cursor().copy("COPY program (job_id, gear_class, template_version, template_hash, name, lines, "
                                "row_ids) FROM STDIN") as copy:
            copy.write_row(forged[:7])
    assert program_count(conn) == 1


# --- what the database checks when a program is stored ----------------------------------------------

def forged(values, **changes):
    """The stored program's values with some changed: job_id, gear_class, version, hash, name, lines,
    row_ids, trace."""
    fields = dict(zip(("job_id", "gear_class", "template_version", "template_hash", "name", "lines", "row_ids",
                       "trace"), values))
    return tuple({**fields, **changes}.values())


def with_line(lines, number, text):
    return [text if index == number else line for index, line in enumerate(lines)]


FORGERIES = [   # (what is forged, changes to the real program, error, words of the message)
    ("hash of other rows", lambda p: {"template_hash": "0123456789abcdef"}, errors.ForeignKeyViolation,
     "has hash"),
    ("a version never stored", lambda p: {"template_version": p["template_version"] + 7},
     errors.ForeignKeyViolation, "is not a stored version"),
    ("another class's version", lambda p: {"gear_class": "helical"}, errors.ForeignKeyViolation,
     "the job is of class spur"),
    ("a job that does not exist", lambda p: {"job_id": -1}, errors.ForeignKeyViolation, "the job does not exist"),
    ("LF inside a line", lambda p: {"lines": with_line(p["lines"], 3, "; X\nG0 X9999 Z-9999")},
     errors.CheckViolation, "line 4 holds a control character"),
    ("CR inside a line", lambda p: {"lines": with_line(p["lines"], 5, "G0 X10\rG0 X9999")},
     errors.CheckViolation, "line 6 holds a control character"),
    ("TAB in a comment", lambda p: {"lines": with_line(p["lines"], 2, "; GEAR\t42")}, errors.CheckViolation,
     "line 3 holds a control character"),
    ("a row its version does not have", lambda p: {"row_ids": [99999] + p["row_ids"][1:]}, errors.CheckViolation,
     "row ids {99999} are not rows of class spur"),
    ("no lines", lambda p: {"lines": [], "row_ids": []}, errors.CheckViolation, "one or more texts"),
]


@pytest.mark.parametrize("changes, error, words", [case[1:] for case in FORGERIES], ids=[c[0] for c in FORGERIES])
def test_a_forged_program_is_refused_by_the_engines_own_path(conn, program, changes, error, words):
    real = stored(conn, program.program_id)
    values = dict(zip(("job_id", "gear_class", "template_version", "template_hash", "name", "lines", "row_ids",
                       "trace"), real))
    with pytest.raises(error, match=re.escape(words)), conn.transaction(), as_role(conn, "engine_runner"):
        submitted(conn, forged(real, **changes(values)))
    assert program_count(conn) == 1


def test_the_real_program_passes_the_same_checks(conn, program):
    with as_role(conn, "engine_runner"):
        again = submitted(conn, stored(conn, program.program_id))
    job_id, gear_class, version, template_hash, name, lines, row_ids, trace = stored(conn, program.program_id)
    assert stored(conn, again) == (job_id, gear_class, version, template_hash, name, renamed(lines, row_ids, again),
                                   row_ids, trace)


def test_a_batch_id_not_drawn_from_the_sequence_is_refused(conn, program):
    values = stored(conn, program.program_id)
    ahead = conn.execute("SELECT last_value + 1000 FROM program_id_seq").fetchone()[0]
    with pytest.raises(errors.CheckViolation, match="not drawn from program_id_seq"), conn.transaction(), \
            as_role(conn, "engine_runner"):
        conn.execute(SUBMIT, (ahead, *values[:5], renamed(values[5], values[6], ahead), values[6], Jsonb(values[7])))


def test_runners_store_single_programs_and_batches_recording_a_stored_version(conn):
    with as_role(conn, "engine_runner"):
        single = instantiate_gear(conn, 42)
        batch = instantiate_gears(conn, 40, 49)
    rows = conn.execute("SELECT p.gear_class, p.template_version, p.template_hash, v.hash, p.stored_role "
                        "FROM program p LEFT JOIN template_version_rows v ON v.gear_class = p.gear_class "
                        "AND v.version = p.template_version ORDER BY p.id").fetchall()
    assert len(rows) == 1 + len(batch) and single.template_hash == rows[0][2]
    assert all(recorded == version_hash and role == "engine_runner" for _, _, recorded, version_hash, role in rows)


def test_who_stored_a_program_is_the_login_person_and_the_role(database_url, login_in):
    login = login_in("engine_runner")
    with psycopg.connect(login.url(database_url)) as conn:
        conn.execute("SET ROLE engine_runner")
        program = instantiate_gear(conn, 42)
        who = conn.execute("SELECT stored_by, stored_role, created_at = now() FROM program WHERE id = %s",
                           (program.program_id,)).fetchone()
        conn.rollback()
    assert who == (login.name, "engine_runner", True)


def test_a_program_made_inside_an_edit_fixes_its_version_and_the_next_edit_makes_another(conn):
    conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; ONE\"' WHERE gear_class = 'spur' AND id = 800")
    made = instantiate_gear(conn, 42, mode=RunMode(draft=True))   # the editor tries each draft
    conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; TWO\"' WHERE gear_class = 'spur' AND id = 800")
    later = instantiate_gear(conn, 42, mode=RunMode(draft=True))
    assert "G90 G71 G94 ; ONE" in made.lines and "G90 G71 G94 ; TWO" in later.lines
    assert later.template_version == made.template_version + 1
    for program in (made, later):   # each records the rows it was made from, stored for its version
        assert stored_version_hash(conn, "spur", program.template_version) == program.template_hash


# --- jobs stay editable, the history is checked -------------------------------------------------------

def test_a_runner_edits_a_jobs_parameters_and_makes_its_program_again(conn, program):
    from engine.programs.remake import instantiate_job

    with as_role(conn, "engine_runner"):
        conn.execute("UPDATE job SET params = jsonb_set(params, '{program_name}', '\"GEAR42B\"') WHERE id = %s",
                     (program.job_id,))
        again = instantiate_job(conn, program.job_id)
    assert again.name == "GEAR42B" and again.job_id == program.job_id


@pytest.mark.parametrize("statement", ["UPDATE job SET confirmed_at = NULL", "UPDATE job SET gear_class = 'helical'",
                                       "INSERT INTO cutting_case (module, teeth, material, hob_material, hob_starts, "
                                       "hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed) "
                                       "VALUES (2, 20, 'C45', 'HSS', 1, 80, 'rough', 100, 1, 1)"])
def test_a_runner_cannot_write_the_history_or_a_jobs_record_by_hand(conn, program, statement):
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_runner"):
        conn.execute(statement)


def test_a_runner_confirms_a_job_the_engine_made(conn, program):
    with as_role(conn, "engine_runner"):
        (case_id,) = confirm_job(conn, program.job_id)
    case = conn.execute("SELECT hob_speed, job_id FROM cutting_case WHERE id = %s", (case_id,)).fetchone()
    assert case == (246, program.job_id)


def set_rough(field, value):
    return f"UPDATE job SET cutting = jsonb_set(cutting, '{{rough,{field}}}', '{value}') WHERE id = %(job)s"


REFUSED_CASES = [   # (why, statements run as the owner first, words of the message)
    ("no program", ["INSERT INTO job (gear_id, gear_class, machine, hob_id, params, cutting) SELECT gear_id, "
                    "gear_class, machine, hob_id, params, cutting FROM job WHERE id = %(job)s"],
                    "has no stored program"),
    ("zero feed", [set_rough("axial_feed", 0)], "need a positive hob_speed, axial_feed and radial_feed"),
    ("negative feed", [set_rough("radial_feed", -36)], "need a positive"),
    ("feed not a number", [set_rough("axial_feed", '"fast"')], "need a positive"),
    ("not the speed its program ran", ["UPDATE job SET cutting = jsonb_set(cutting, '{hob_speed}', '400') "
                                       "WHERE id = %(job)s"], "its last program ran n0 = 246"),
    ("hob spindle limit", ["UPDATE machine SET spindle_max = 200 WHERE name = 'hobber-840d'"],
     "exceeds hobber-840d's hob spindle maximum 200"),
    ("table speed limit", ["UPDATE machine SET table_speed_max = 10 WHERE name = 'hobber-840d'"],
     "table speed 12.9 r/min exceeds"),   # 246 r/min x 1 start / 19 teeth (§B4)
]


@pytest.mark.parametrize("statements, words", [case[1:] for case in REFUSED_CASES], ids=[c[0] for c in REFUSED_CASES])
def test_a_job_that_cannot_vouch_for_its_cutting_data_is_not_a_case(conn, program, statements, words):
    for statement in statements:
        conn.execute(statement, {"job": program.job_id})
    job_id = conn.execute("SELECT max(id) FROM job").fetchone()[0]
    cases = conn.execute("SELECT count(*) FROM cutting_case").fetchone()[0]
    with pytest.raises(EngineError, match=re.escape(words)), as_role(conn, "engine_runner"):
        confirm_job(conn, job_id)
    assert conn.execute("SELECT count(*) FROM cutting_case").fetchone()[0] == cases


def cutting_speed(tip_diameter, hob_speed):
    """v = π·d_a0·n0/1000 in m/min (reference §B4)."""
    return math.pi * tip_diameter * hob_speed / 1000


def feed_per_rev(feed, hob_speed, starts, teeth):
    """f = v_f/n2 with n2 = n0·z0/z2, mm per workpiece revolution (§B5)."""
    return feed / (hob_speed * starts / teeth)


# (hob speed r/min, axial mm/min, radial mm/min) on m 2, z 19, 1-start d_a0 70 (the paper's setup)
CASE_VALUES = [(246, 105, 36), (2800, 105, 36), (2700, 105, 36), (246, 259, 36), (246, 258, 36),
               (246, 105, 600), ("NaN", 105, 36), (246, "Infinity", 36), (246, 105, "-Infinity")]


@pytest.mark.parametrize("speed, axial, radial", CASE_VALUES)
def test_every_case_is_physically_plausible_whoever_adds_it(conn, speed, axial, radial):
    numbers = [float(value) for value in (speed, axial, radial)]
    plausible = (all(math.isfinite(value) and value > 0 for value in numbers)
                 and cutting_speed(70, numbers[0]) <= 600
                 and all(feed_per_rev(feed, numbers[0], 1, 19) <= 10 * 2 for feed in numbers[1:]))
    insert = ("INSERT INTO cutting_case (module, teeth, material, hob_material, hob_starts, hob_tip_diameter, cut, "
              "hob_speed, axial_feed, radial_feed) VALUES (2, 19, '40Cr', 'HSS', 1, 70, 'rough', %s, %s, %s)")
    if plausible:
        conn.execute(insert, (speed, axial, radial))
        return
    with pytest.raises(errors.CheckViolation, match="violates check constraint"), conn.transaction():
        conn.execute(insert, (speed, axial, radial))


def test_a_job_whose_program_does_not_record_its_hob_speed_is_not_a_case(conn, program):
    """The case's speed must be one a program ran: without n0 in the trace nothing vouches for it."""
    values = stored(conn, program.program_id)
    submitted(conn, (*values[:7], {}))
    with pytest.raises(EngineError, match="does not record the hob speed it ran"), as_role(conn, "engine_runner"):
        confirm_job(conn, program.job_id)
    assert conn.execute("SELECT count(*) FROM cutting_case WHERE job_id = %s", (program.job_id,)).fetchone()[0] == 0
