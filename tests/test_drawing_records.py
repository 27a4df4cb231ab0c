"""Drawing records (issue 26): the turning proof reads the part, blank, tool-change position and
materials from the drawing `engine import-dxf` stored, never from job.params, which a runner may
edit in SQL. A job whose params disagree with its drawing record is refused in one line (exit 1,
nothing stored); the record itself is never changed or deleted, by any role."""
from __future__ import annotations

import hashlib
import json
import math
import shutil

import psycopg
import pytest
from helpers.outcomes import counts, one_line_refusal
from helpers.roles import as_role
from psycopg import errors
from psycopg.types.json import Jsonb

from engine.db.migrate import migrate
from engine.machines.turning_cutting import turning_cut_problem
from engine.paths import MIGRATIONS_DIR, SAMPLE_DRAWING

SAMPLE_BLANK_DIAMETER = 44.0   # mm, seed_templates/drawings/README.md


def _sample_job(run, *options) -> int:
    made = run("import-dxf", SAMPLE_DRAWING, "--json", *options)
    assert made.exit_code == 0, made.output
    return json.loads(made.stdout)["job_id"]


def _update(url, job_id, assignment: str, *values) -> None:
    with psycopg.connect(url) as conn:
        conn.execute(f"UPDATE job SET {assignment} WHERE id = %s", (*values, job_id))   # test SQL, constant text


def test_a_runner_declaring_aluminium_to_run_a_steel_part_fast_is_refused(run):
    """S3999 at F1200 on the Ø44 blank: vc = π·44·3999/1000 = 553 m/min, f = 1200/3999 = 0.30
    mm/rev, beyond carbide on steel (80-380 m/min, reference §E1), inside it on aluminium."""
    vc, feed = math.pi * SAMPLE_BLANK_DIAMETER * 3999 / 1000, 1200 / 3999
    assert turning_cut_problem("ROUGH", "carbide", "steel", vc, feed) is not None
    assert turning_cut_problem("ROUGH", "carbide", "aluminium", vc, feed) is None
    job_id = _sample_job(run)
    _update(run.url, job_id, "params = jsonb_set(params, '{workpiece_material}', '\"aluminium\"'), module_params = "
            "jsonb_set(jsonb_set(module_params, '{cutcond:1,spindle_rpm}', '3999'), '{cutmotion:1,feed}', '1200')")
    before = counts(run.url)
    refused = one_line_refusal(run("instantiate", "--job", job_id))
    assert f"job {job_id}" in refused and "params.workpiece_material = 'aluminium' is not 'steel'" in refused
    assert "--material" in refused and counts(run.url) == before


def test_the_same_cutting_data_pass_on_the_drawing_imported_as_aluminium(run):
    """A materials change is an import with --material: a new drawing record and a new job."""
    job_id = _sample_job(run, "--material", "aluminium")
    _update(run.url, job_id, "module_params = jsonb_set(jsonb_set(module_params, '{cutcond:1,spindle_rpm}', "
            "'3999'), '{cutmotion:1,feed}', '1200')")
    made = run("instantiate", "--job", job_id)
    assert made.exit_code == 0, made.output


def test_a_shrunk_profile_is_refused(run):
    job_id = _sample_job(run)
    with psycopg.connect(run.url) as conn:
        params = conn.execute("SELECT params FROM job WHERE id = %s", (job_id,)).fetchone()[0]
    drawn = params["profile"]
    # every radius (r0, r1 and an arc's centre rc: values 2, 4 and 6 of a segment) 0.5 mm smaller
    params["profile"] = [[value - 0.5 if index in (2, 4, 6) and not isinstance(value, bool) else value
                          for index, value in enumerate(segment)] for segment in drawn]
    _update(run.url, job_id, "params = %s", Jsonb(params))
    before = counts(run.url)
    refused = one_line_refusal(run("instantiate", "--job", job_id))
    assert f"job {job_id}: params.profile[0] = " in refused and repr(drawn[0]) in refused
    assert counts(run.url) == before


def test_a_turning_job_without_its_drawing_record_is_refused(run):
    """A runner's INSERT copying a job's params leaves drawing_id out: no record to prove against."""
    job_id = _sample_job(run)
    with psycopg.connect(run.url) as conn:
        copy = conn.execute("INSERT INTO job (gear_class, machine, params, module_params) SELECT gear_class, "
                            "machine, params, module_params FROM job WHERE id = %s RETURNING id",
                            (job_id,)).fetchone()[0]
    before = counts(run.url)
    assert "without a drawing record" in one_line_refusal(run("instantiate", "--job", copy))
    assert counts(run.url) == before


def test_import_dxf_stores_one_drawing_record_with_the_files_sha256(run):
    before = _drawings(run.url)
    job_id = _sample_job(run)
    with psycopg.connect(run.url) as conn:
        row = conn.execute("SELECT d.file_name, d.sha256, d.profile, d.workpiece_material, "
                           "d.imported_by = current_user, j.params "
                           "FROM job j JOIN drawing d ON d.id = j.drawing_id WHERE j.id = %s",
                           (job_id,)).fetchone()
    file_name, sha256, profile, material, by_me, params = row
    assert _drawings(run.url) == before + 1 and file_name == SAMPLE_DRAWING.name and by_me
    assert sha256 == hashlib.sha256(SAMPLE_DRAWING.read_bytes()).hexdigest()
    assert profile == params["profile"] and material == params["workpiece_material"] == "steel"


def _drawings(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM drawing").fetchone()[0]


@pytest.mark.parametrize("role", ["engine_editor", "engine_runner", "engine_releaser", None])
@pytest.mark.parametrize("change", ["UPDATE drawing SET workpiece_material = 'aluminium'", "DELETE FROM drawing",
                                    "TRUNCATE drawing CASCADE"])
def test_no_role_changes_or_deletes_a_drawing_record(conn, role, change):
    """None: the owner (the role running the migrations), stopped by the trigger."""
    conn.execute("INSERT INTO drawing (file_name, profile) VALUES ('a.dxf', '[]')")
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction():
        if role is None:
            conn.execute(change)
        else:
            with as_role(conn, role):
                conn.execute(change)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_migration_0027_makes_a_record_for_each_job_made_from_a_drawing(empty_database_url, tmp_path):
    folder = tmp_path / "migrations"
    shutil.copytree(MIGRATIONS_DIR, folder)
    later = {path.name: path.read_text() for path in folder.glob("*.sql") if path.name >= "0027"}
    for name in later:
        (folder / name).unlink()
    profile = [["line", 0.0, 0.0, 0.0, 8.0], ["arc", 0.0, 8.0, -2.0, 10.0, -2.0, 8.0, False]]
    params = {"drawing": "old.dxf", "units": "mm", "profile": profile, "stock_diameter": 24.0, "stock_z_front": 0.5,
              "stock_z_back": -12.0, "tool_change_x": 100.0, "tool_change_z": 50.0, "workpiece_material": "brass"}
    with psycopg.connect(empty_database_url) as conn:
        migrate(conn, folder)
        conn.execute("INSERT INTO gear_class (name) VALUES ('turning_iso')")
        conn.execute("INSERT INTO machine (name, kind, dialect, x_min, x_max, z_min, z_max, spindle_max) "
                     "VALUES ('lathe-old', 'lathe', 'iso', 0, 300, -300, 300, 4000)")
        insert = ("INSERT INTO job (gear_class, machine, params, module_params) VALUES ('turning_iso', 'lathe-old', "
                  "%s, %s) RETURNING id")
        turning = conn.execute(insert, (Jsonb(params), Jsonb({"prep:2": {"tool": 2, "tool_material": "hss"}})))
        turning_id = turning.fetchone()[0]
        other_id = conn.execute(insert, (Jsonb({"n0": 300}), Jsonb({}))).fetchone()[0]
        conn.commit()
        for name, text in later.items():
            (folder / name).write_text(text)
        migrate(conn, folder)
        record = conn.execute(
            "SELECT d.file_name, d.sha256, d.profile, d.stock_diameter, d.stock_z_front, d.stock_z_back, "
            "d.tool_change_x, d.tool_change_z, d.workpiece_material, d.tool_materials, d.imported_by "
            "FROM job j JOIN drawing d ON d.id = j.drawing_id WHERE j.id = %s", (turning_id,)).fetchone()
        assert record == ("old.dxf", None, profile, 24.0, 0.5, -12.0, 100.0, 50.0, "brass", {"2": "hss"},
                          "migration 0027")
        assert conn.execute("SELECT drawing_id FROM job WHERE id = %s", (other_id,)).fetchone()[0] is None
        assert conn.execute("SELECT count(*) FROM drawing").fetchone()[0] == 1
        made = conn.execute("INSERT INTO drawing (file_name, profile) VALUES ('new.dxf', '[]') RETURNING id")
        assert made.fetchone()[0] > turning_id   # the sequence continues after the ids the backfill took


def test_the_proof_takes_the_records_facts_and_the_jobs_cutting_data():
    """What the simulation is handed (engine.simulation.turning.drawing.proof_params): the part,
    blank, tool-change position and materials of the record, the speeds and feeds of the job."""
    from engine.simulation.turning.drawing import DRAWING_FACTS, DrawingRecord, proof_params

    recorded = {"profile": [["line", 0.0, 0.0, 0.0, 8.0]], "stock_diameter": None, "stock_z_front": 0.0,
                "stock_z_back": -10.0, "tool_change_x": 100.0, "tool_change_z": 50.0, "workpiece_material": "steel"}
    assert set(recorded) == set(DRAWING_FACTS)
    record = DrawingRecord(1, "a.dxf", recorded, {"1": "carbide"})
    edited = {**recorded, "profile": [["line", 0.0, 0.0, 0.0, 7.0]], "stock_diameter": 30.0,
              "workpiece_material": "aluminium", "clearance": 1.0}
    modules = {"prep:1": {"tool": 1, "tool_material": "hss"}, "cutcond:1": {"spindle_rpm": 3999}}
    params, module_params = proof_params(record, edited, modules)
    assert params["profile"] == recorded["profile"] and params["workpiece_material"] == "steel"
    assert "stock_diameter" not in params and params["clearance"] == 1.0   # NULL: the blank is assumed
    assert module_params == {"prep:1": {"tool": 1, "tool_material": "carbide"}, "cutcond:1": {"spindle_rpm": 3999}}
    assert modules["prep:1"]["tool_material"] == "hss"   # the job's own values are not changed


def test_jobs_show_says_where_a_job_s_drawing_record_came_from(run):
    """Third adversary: a runner may insert a drawing record by hand and a job that names it (the
    import runs with a runner's rights). The record cannot be refused, but it says so: `jobs show`
    gives a file import's hash, and 'no file hash' with the login for a record typed in SQL."""
    imported = _sample_job(run)
    digest = hashlib.sha256(SAMPLE_DRAWING.read_bytes()).hexdigest()
    shown = json.loads(run("jobs", "show", imported, "--json").stdout)["job"]["drawing"]
    assert SAMPLE_DRAWING.name in shown and f"file sha256 {digest[:16]}" in shown
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        typed = conn.execute("INSERT INTO drawing (file_name, profile) SELECT file_name, profile FROM drawing "
                             "WHERE id = (SELECT drawing_id FROM job WHERE id = %s) RETURNING id, imported_by",
                             (imported,)).fetchone()
        job_id = conn.execute("INSERT INTO job (gear_class, machine, params, module_params, drawing_id) "
                              "SELECT gear_class, machine, params, module_params, %s FROM job WHERE id = %s "
                              "RETURNING id", (typed[0], imported)).fetchone()[0]
    shown = run("jobs", "show", job_id).stdout
    assert f"drawing:           {typed[0]}: " in shown and "no file hash (typed in SQL" in shown
    assert f"by {typed[1]} at" in shown


THREAD = "cutmotion:4"   # the sample's THREAD operation (layer 4, seed_templates/drawings/README.md)
M20_PITCH = 1.5          # mm, M20×1.5: the drawing's @P
M20_ROOT = 20 - 2 * (17 / 24) * math.sqrt(3) / 2 * M20_PITCH   # d3 = d − 2·h3, h3 = 0.61343·P (ISO 68-1): Ø18.16


def _thread(url, job_id) -> dict:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT module_params->%s FROM job WHERE id = %s", (THREAD, job_id)).fetchone()[0]


def test_a_runners_thread_pitch_edit_is_refused(run):
    """A pitch of 2.0 on the drawn M20×1.5 rendered G32 … F2.0000 and was stored as MATCH."""
    job_id = _sample_job(run)
    assert _thread(run.url, job_id)["thread_pitch"] == M20_PITCH
    _update(run.url, job_id, "module_params = jsonb_set(module_params, '{cutmotion:4,thread_pitch}', '2.0')")
    before = counts(run.url)
    refused = one_line_refusal(run("instantiate", "--job", job_id))
    assert f"job {job_id}: module_params.cutmotion:4.thread_pitch = 2.0 is not 1.5" in refused
    assert counts(run.url) == before


def test_a_runners_root_line_edit_is_refused(run):
    """The root line moved from r = d3/2 (Ø18.16) to r = 7.5 (Ø15) would cut the thread 1.6 mm too deep."""
    job_id = _sample_job(run)
    thread = _thread(run.url, job_id)
    radii = sorted({value for path in thread["paths"] for segment in path for value in segment[2:5:2]})
    assert math.isclose(radii[0], M20_ROOT / 2, abs_tol=0.01)   # the drawn root line
    thread["paths"] = [[[*segment[:2], 7.5 if math.isclose(segment[2], radii[0]) else segment[2], segment[3],
                         7.5 if math.isclose(segment[4], radii[0]) else segment[4], *segment[5:]]
                        for segment in path] for path in thread["paths"]]
    _update(run.url, job_id, "module_params = jsonb_set(module_params, '{cutmotion:4}', %s)", Jsonb(thread))
    before = counts(run.url)
    refused = one_line_refusal(run("instantiate", "--job", job_id))
    assert f"job {job_id}: module_params.cutmotion:4.paths = " in refused and "7.5" in refused
    assert counts(run.url) == before


def test_the_sample_with_its_drawn_thread_is_made_again(run):
    job_id = _sample_job(run)
    with psycopg.connect(run.url) as conn:
        threads = conn.execute("SELECT d.threads FROM job j JOIN drawing d ON d.id = j.drawing_id WHERE j.id = %s",
                               (job_id,)).fetchone()[0]
    drawn = _thread(run.url, job_id)
    assert threads == {"4": {"thread_pitch": drawn["thread_pitch"], "paths": drawn["paths"]}}
    made = run("instantiate", "--job", job_id)
    assert made.exit_code == 0, made.output


def test_migration_0028_records_the_threads_of_the_job_stored_with_each_drawing(empty_database_url, tmp_path):
    """A record a job names gets that job's THREAD operations ({} for none); one no job names stays
    NULL (not recorded: the proof reads module_params, as before)."""
    folder = tmp_path / "migrations"
    shutil.copytree(MIGRATIONS_DIR, folder)
    later = {path.name: path.read_text() for path in folder.glob("*.sql") if path.name >= "0028"}
    for name in later:
        (folder / name).unlink()
    lines = [[["line", -2.0, 10.0, -20.0, 10.0]], [["line", -2.0, 9.08, -20.0, 9.08]]]
    thread = {"kind": "THREAD", "paths": lines, "thread_pitch": 1.5, "depth_per_pass": 0.2}
    params = {"drawing": "old.dxf", "profile": [["line", 0.0, 0.0, 0.0, 10.0]]}
    with psycopg.connect(empty_database_url) as conn:
        migrate(conn, folder)
        conn.execute("INSERT INTO gear_class (name) VALUES ('turning_iso')")
        conn.execute("INSERT INTO machine (name, kind, dialect, x_min, x_max, z_min, z_max, spindle_max) "
                     "VALUES ('lathe-old', 'lathe', 'iso', 0, 300, -300, 300, 4000)")
        drawings = [conn.execute("INSERT INTO drawing (file_name, profile) VALUES (%s, '[]') RETURNING id",
                                 (name,)).fetchone()[0] for name in ("threaded.dxf", "plain.dxf", "unused.dxf")]
        insert = ("INSERT INTO job (gear_class, machine, params, module_params, drawing_id) VALUES ('turning_iso', "
                  "'lathe-old', %s, %s, %s)")
        conn.execute(insert, (Jsonb(params), Jsonb({"cutmotion:4": thread, "cutmotion:1": {"kind": "ROUGH"}}),
                              drawings[0]))
        conn.execute(insert, (Jsonb(params), Jsonb({"cutmotion:1": {"kind": "ROUGH"}}), drawings[1]))
        conn.commit()
        for name, text in later.items():
            (folder / name).write_text(text)
        migrate(conn, folder)
        recorded = dict(conn.execute("SELECT id, threads FROM drawing").fetchall())
        with pytest.raises(errors.InsufficientPrivilege):   # the records are records again
            conn.execute("UPDATE drawing SET threads = NULL")
    assert recorded == {drawings[0]: {"4": {"thread_pitch": 1.5, "paths": lines}}, drawings[1]: {},
                        drawings[2]: None}


def test_the_proof_takes_the_records_thread_and_the_jobs_depth_per_pass():
    from engine.simulation.turning.drawing import DrawingRecord, proof_params

    lines = [[["line", -2.0, 10.0, -20.0, 10.0]], [["line", -2.0, 9.08, -20.0, 9.08]]]
    record = DrawingRecord(1, "a.dxf", {}, None, {"4": {"thread_pitch": 1.5, "paths": lines}})
    edited = {"cutmotion:4": {"kind": "THREAD", "thread_pitch": 2.0, "paths": [], "depth_per_pass": 0.1}}
    _, module_params = proof_params(record, {}, edited)
    assert module_params["cutmotion:4"] == {"kind": "THREAD", "thread_pitch": 1.5, "paths": lines,
                                            "depth_per_pass": 0.1}
    unrecorded = DrawingRecord(1, "a.dxf", {}, None, None)   # a record made before migration 0028
    assert proof_params(unrecorded, {}, edited)[1] == edited
