"""A stored program is evidence only when it is proved now (issue 26, finding 9, second round).

A runner can INSERT a job by hand and store, through program_submission, the very program the
engine renders from it: the lines are the rendering (MATCH of old), but no verifier read them.
The check proves the rendering as a new program is proved (the machine's verifier, the
simulation) and says REFUSED when the proof refuses it; lists never say a verifier read a program
they did not check; a job of a shape the engine never stores is refused in one line, never a
crash; a program stored with no trace is not the rendering."""
import json

import psycopg
import pytest
from helpers.roles import as_role
from psycopg.types.json import Jsonb

from engine.nc.lineage import lineage_line, lineage_words
from engine.programs.rendering import Renderer, StoredProgram

GEAR = 42                  # the seeded spur gear, made on hobber-840d
FAST_N0 = 1240             # r/min: over hobber-840d's hob spindle maximum (its machine record, read below)
# r/min: under it, but v = π·70·900/1000 ≈ 198 m/min, far above the hob's reference range: a new job's
# bounds (engine.programs.job_checks, as `instantiate --job` holds a stored job) refuse it
BOUNDED_N0 = 900


def made(run) -> tuple[int, int]:
    result = run("instantiate", "--gear", GEAR, "--json")
    assert result.exit_code == 0, result.output
    found = json.loads(result.stdout)
    return found["job_id"], found["program_id"]


def hand_job(conn, job_id: int, params: dict | None = None, module_params: dict | None = None,
             cutting: dict | None = None) -> int:
    """A copy of the job INSERTed as a runner can, its params/module_params/cutting updated."""
    gear_id, cls, machine, hob, p, m, c = conn.execute(
        "SELECT gear_id, gear_class, machine, hob_id, params, module_params, cutting FROM job WHERE id = %s",
        (job_id,)).fetchone()
    return conn.execute(
        "INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params, cutting) "
        "VALUES (%s, %s, %s, %s, %s, %s, %s) RETURNING id",
        (gear_id, cls, machine, hob, Jsonb({**p, **(params or {})}), Jsonb({**m, **(module_params or {})}),
         Jsonb({**(c or {}), **(cutting or {})}))).fetchone()[0]


def hand_program(conn, job_id: int, trace: bool = True) -> int:
    """The job's rendering by its class's released version, stored through program_submission as
    verified (unverified false), as a runner can; `trace` False stores it without its trace."""
    cls, machine, params, module_params, dialect, digest, version = conn.execute(
        "SELECT j.gear_class, j.machine, j.params, j.module_params, m.dialect, job_input_hash(j.params, "
        "j.module_params), (SELECT max(version) FROM template_version_rows v WHERE v.gear_class = j.gear_class) "
        "FROM job j JOIN machine m ON m.name = j.machine WHERE j.id = %s", (job_id,)).fetchone()
    program_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    renderer = Renderer(conn)
    template = renderer.template(cls, version)
    stored = StoredProgram(program_id, "HAND", cls, version, template.hash, digest, False, False, [], [], None,
                           job_id, machine, params, module_params, digest, True, dialect)
    lines, row_ids, made_trace = renderer.rendered(stored, template)
    conn.execute("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, "
                 "lines, row_ids, trace, unverified) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s, false)",
                 (program_id, job_id, cls, version, template.hash, "HAND", lines, row_ids,
                  Jsonb(made_trace) if trace else None))
    return program_id


@pytest.fixture(params=[FAST_N0, BOUNDED_N0])
def over_speed(run, request):
    """(job, program): a hand job with n0 over the hob spindle maximum (or over a new job's
    bounds), and its rendering stored."""
    job_id, _ = made(run)
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        fast = hand_job(conn, job_id, params={"n0": request.param}, cutting={"hob_speed": request.param})
        program_id = hand_program(conn, fast)
    with psycopg.connect(run.url) as conn:
        maximum = conn.execute("SELECT spindle_max FROM machine WHERE name = 'hobber-840d'").fetchone()[0]
    assert (request.param > maximum) == (request.param == FAST_N0)   # the verifier's case, and the bounds' one
    return fast, program_id


def test_a_hand_stored_rendering_the_verifier_refuses_is_refused_not_match(run, over_speed, tmp_path):
    job_id, program_id = over_speed
    shown = run("programs", "show", program_id)
    assert shown.exit_code == 0, shown.output
    rendering = next(line for line in shown.stdout.splitlines() if line.startswith("rendering:"))
    assert rendering.split()[1] == "REFUSED:" and "MATCH" not in rendering
    assert "read by the machine's verifier" not in shown.stdout
    checked = json.loads(run("programs", "list", "--job", job_id, "--check", "--json").stdout)["programs"]
    assert [(p["rendering"], p["verifier"]) for p in checked] == [("REFUSED", "-")]
    for command in (("simulate", "--program", program_id), ("explain", "--program", program_id),
                    ("plot", "--program", program_id, "-o", tmp_path / "p.svg"),
                    ("cases", "confirm", "--job", job_id)):
        result = run(*command)
        assert result.exit_code == 1, (command, result.output)
        assert len(result.stderr.strip().splitlines()) == 1 and "REFUSED" in result.stderr, command
    assert not (tmp_path / "p.svg").exists()


def test_lists_say_a_program_not_checked_is_only_stored_as_verified(run):
    job_id, program_id = made(run)
    plain = json.loads(run("programs", "list", "--job", job_id, "--json").stdout)["programs"]
    assert [(p["rendering"], p["verifier"]) for p in plain] == [("on show", "stored as verified, unchecked")]
    job = json.loads(run("jobs", "show", job_id, "--json").stdout)["job"]["programs"]
    assert [p["verifier"] for p in job] == ["stored as verified, unchecked"]
    table = run("programs", "list", "--job", job_id)
    assert table.exit_code == 0 and " read " not in f" {table.stdout} "
    checked = json.loads(run("programs", "list", "--job", job_id, "--check", "--json").stdout)["programs"]
    assert [(p["rendering"], p["verifier"]) for p in checked] == [("MATCH", "read")]


def test_a_program_stored_without_its_trace_is_a_mismatch_and_explain_says_so(run):
    job_id, _ = made(run)
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        program_id = hand_program(conn, job_id, trace=False)
    shown = json.loads(run("programs", "show", program_id, "--json").stdout)["programs"][0]
    assert shown["rendering"]["status"] == "MISMATCH" and "trace" in shown["rendering"]["reason"]
    explained = run("explain", "--program", program_id)
    assert explained.exit_code == 1 and "before programs kept their trace" not in explained.stderr


MALFORMED = [({"cutmotion:1": "x"}, {"cycle_time": 1}), ({"cutmotion:1": None}, {"cycle_time": 1}),
             ({"cutmotion:1": {"feed_axial": "a"}}, {"cycle_time": 1}), ({"cutmotion:1": "x"}, {})]


@pytest.mark.parametrize("module_params,params", MALFORMED)
def test_a_hand_job_of_a_shape_the_engine_never_stores_is_refused_in_one_line(run, tmp_path, module_params,
                                                                             params):
    job_id, _ = made(run)
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        bad = hand_job(conn, job_id, params=params, module_params=module_params)
        program_id = junk_program(conn, bad)
    for command in (("instantiate", "--job", bad), ("plot", "--job", bad, "-o", tmp_path / "j.svg"),
                    ("cases", "confirm", "--job", bad),
                    ("simulate", "--program", program_id), ("explain", "--program", program_id),
                    ("instantiate", "--jobs", f"{bad}-{bad}")):
        result = run(*command)
        assert result.exit_code == 1, (command, result.output)
        message = result.stderr.strip()
        assert len(message.splitlines()) == 1 and f"job {bad}" in message, (command, message)
        assert "module_params.cutmotion:1" in message, (command, message)
    shown = json.loads(run("programs", "show", program_id, "--json").stdout)["programs"][0]["rendering"]
    assert shown["status"] == "UNCHECKED" and "module_params.cutmotion:1" in shown["reason"]
    listed = json.loads(run("programs", "list", "--job", bad, "--check", "--json").stdout)["programs"]
    assert [(p["rendering"], p["verifier"]) for p in listed] == [("UNCHECKED", "-")]


def junk_program(conn, job_id: int) -> int:
    """A program stored by hand for the job: its lineage line and M30 (the database takes it)."""
    cls, dialect, digest, version, template_hash, rows = conn.execute(
        "SELECT j.gear_class, m.dialect, job_input_hash(j.params, j.module_params), v.version, v.hash, "
        "v.rows FROM job j JOIN machine m ON m.name = j.machine JOIN template_version_rows v "
        "ON v.gear_class = j.gear_class WHERE j.id = %s ORDER BY v.version DESC LIMIT 1", (job_id,)).fetchone()
    program_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    words = lineage_words(program_id, cls, version, template_hash, digest, False, False)
    conn.execute("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, "
                 "lines, row_ids, trace, unverified) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s, false)",
                 (program_id, job_id, cls, version, template_hash, "JUNK", [lineage_line(words, dialect), "M30"],
                  [-1, rows[0]["id"]], Jsonb({})))
    return program_id


def program_count(url: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM program").fetchone()[0]


def test_an_out_path_the_system_refuses_is_one_line_and_nothing_stored(read_only_run, tmp_path):
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    (tmp_path / "file").write_text("")
    long_name = tmp_path / ("a" * 300)   # over NAME_MAX (255) of every Linux file system
    for out in (long_name, f"{long_name}/", f"{tmp_path / 'loop'}/x", f"{tmp_path / 'loop'}/"):
        before = program_count(read_only_run.url)
        result = read_only_run("instantiate", "--gear", GEAR, "--out", out)
        assert result.exit_code == 1, (out, result.output)
        message = result.stderr.strip()
        assert len(message.splitlines()) == 1 and "nothing stored" in message and len(message) < 300, message
        assert program_count(read_only_run.url) == before


def test_cases_confirm_refuses_feeds_in_job_cutting_the_program_never_ran(run):
    """The runner's job: the engine's own parameters (its program MATCH and proved), job.cutting's
    rough feeds set to 150 and 90 mm/min; the program cuts at the feeds of its module parameters."""
    job_id, _ = made(run)
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        forged = hand_job(conn, job_id, cutting={"rough": {"axial_feed": 150.0, "radial_feed": 90.0}})
        hand_program(conn, forged)
        ran = conn.execute("SELECT module_params->'cutmotion:2'->>'feed_axial' FROM job WHERE id = %s",
                           (forged,)).fetchone()[0]
    assert abs(float(ran) - 150.0) > 1
    before = program_count(run.url), case_count(run.url)
    result = run("cases", "confirm", "--job", forged)
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and "axial_feed 150.0" in message and ran in message, message
    assert (program_count(run.url), case_count(run.url)) == before
    genuine = run("cases", "confirm", "--job", job_id)   # the engine's own job and cutting data: confirmed
    assert genuine.exit_code == 0, genuine.output


def case_count(url: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM cutting_case").fetchone()[0]


COOLANT_OFF_ROW = 2900   # seed_templates/classes/spur.csv: `"M9"` when coolant; no golden test reads it
COMMENTED = "M9 ; COOLANT OFF"


def test_the_impact_of_a_draft_is_not_hidden_by_a_forged_stored_program(run):
    """An editor's draft comments spur's coolant-off line; a runner stores for job 1 a program whose
    lines are already the draft's (`M9 ; COOLANT OFF` where the released version makes `M9`: a
    MISMATCH). The impact compares the draft with the released version rendered now, so job 1
    still shows its change."""
    job_id, genuine = made(run)
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = %s",
                     (f'"{COMMENTED}"', COOLANT_OFF_ROW))
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        lines, row_ids, trace, version, digest = conn.execute(
            "SELECT lines, row_ids, trace, template_version, template_hash FROM program WHERE id = %s",
            (genuine,)).fetchone()
        assert "M9" in lines
        forged_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
        kept = [(COMMENTED if line == "M9" else line.replace(f"PROGRAM {genuine} ", f"PROGRAM {forged_id} "), row)
                for line, row in zip(lines, row_ids)]
        conn.execute("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, "
                     "lines, row_ids, trace) VALUES (%s, %s, 'spur', %s, %s, 'GEAR42', %s, %s, %s)",
                     (forged_id, job_id, version, digest, [line for line, _ in kept], [row for _, row in kept],
                      Jsonb(trace)))
    dry = run("template", "release", "--class", "spur", "--dry-run", "--json")
    assert dry.exit_code == 0, dry.output
    impact = json.loads(dry.stdout)["impact"]
    assert impact["changed"] == 1 and [diff["job_id"] for diff in impact["diffs"]] == [job_id], impact
    assert f"+{COMMENTED}" in impact["diffs"][0]["diff"]


def test_an_out_folder_the_user_may_not_read_is_one_line_and_nothing_stored(read_only_run, tmp_path, monkeypatch):
    """EACCES listing --out (the tests run as root, who reads every folder: the refusal is simulated)."""
    import engine.programs.outputs as outputs

    def refused(path):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(outputs.os, "listdir", refused)
    before = program_count(read_only_run.url)
    result = read_only_run("instantiate", "--gear", GEAR, "--out", f"{tmp_path}/")
    assert result.exit_code == 1, result.output
    assert "Permission denied" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert program_count(read_only_run.url) == before
