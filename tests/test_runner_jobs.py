"""A runner's job is re-derived, not trusted, and a draft never reaches a file (issue 26,
findings 1 and 8).

A runner may INSERT a job (role engine_runner). `engine instantiate --job/--jobs` checks its hob
with the planner's own hob matching, its gear, hob and machine values against the records, and
its edited speeds and feeds against a new job's bounds, with one-line refusals naming the job and
the parameter; nothing stored, no file. An editor's `--draft` prints or dry-runs; with --out or
the config file's machine folder it is refused."""
import json

import psycopg
import pytest
from helpers.roles import as_role

JOB_COPY = """INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params)
              SELECT gear_id, gear_class, machine, %s, params || %s::jsonb, module_params || %s::jsonb
              FROM job WHERE id = %s RETURNING id"""


def made_job(run, *options) -> int:
    made = run("instantiate", "--gear", 42, "--json", *options)
    assert made.exit_code == 0, made.output
    return json.loads(made.stdout)["job_id"]


def runners_copy(run, job_id: int, hob_id: str | None = None, params: dict | None = None,
                 module_params: dict | None = None) -> int:
    """A copy of the job stored by the runner role in SQL, its hob and some parameters replaced."""
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        hob = hob_id or conn.execute("SELECT hob_id FROM job WHERE id = %s", (job_id,)).fetchone()[0]
        return conn.execute(JOB_COPY, (hob, json.dumps(params or {}), json.dumps(module_params or {}),
                                       job_id)).fetchone()[0]


def one_value(run, query: str, *args):
    with psycopg.connect(run.url) as conn:
        return conn.execute(query, args).fetchone()[0]


def program_count(run) -> int:
    return one_value(run, "SELECT count(*) FROM program")


def refused(result, *words) -> str:
    message = result.stderr
    assert result.exit_code == 1, result.output
    assert message.count("\n") == 1 and "Traceback" not in result.output, message
    for word in words:
        assert word in message, message
    return message


@pytest.mark.parametrize("hob_id", ["H-M2.5-AA-R1", "H-M3-AA-R1"])
@pytest.mark.parametrize("batch", [False, True], ids=["job", "jobs"])
def test_a_runners_copy_naming_a_hob_of_another_module_is_refused(run, tmp_path, hob_id, batch):
    """Gear 42 is m 2: a hob of m 2.5 or m 3 cuts another tooth. The copy of its job naming one is
    refused as `engine hobs match` refuses that hob for the gear; nothing stored, no file."""
    job = made_job(run)
    copy = runners_copy(run, job, hob_id)
    module = one_value(run, "SELECT module FROM gear WHERE id = 42")
    hob_module = one_value(run, "SELECT module FROM hob WHERE id = %s", hob_id)
    assert abs(float(hob_module) - float(module)) > 0.4   # the planner would never pick it
    before, out = program_count(run), tmp_path / "nc"
    target = ("--jobs", f"{job}-{copy}") if batch else ("--job", copy)
    refused(run("instantiate", *target, "--out", out), f"job {copy}", hob_id, f"module {float(module):g}",
            f"module {float(hob_module):g}")
    assert program_count(run) == before and not (out.exists() and any(out.iterdir()))


def test_a_runners_copy_stating_another_module_than_the_gear_is_refused(run, tmp_path):
    """The job's mn is the gear's module, not a choice: a value the records do not give is refused."""
    job = made_job(run)
    copy = runners_copy(run, job, params={"mn": 2.5})
    before = program_count(run)
    refused(run("instantiate", "--job", copy, "--out", tmp_path / "nc"), f"job {copy}", "params.mn")
    assert program_count(run) == before and not (tmp_path / "nc").exists()


def test_a_hob_speed_edited_beyond_the_machine_is_refused_as_a_new_jobs(run):
    job = made_job(run)
    spindle_max = one_value(run, "SELECT spindle_max FROM machine WHERE name = 'hobber-840d'")
    copy = runners_copy(run, job, params={"n0": int(spindle_max) + 1})
    before = program_count(run)
    refused(run("instantiate", "--job", copy), f"job {copy}, params.n0", f"{int(spindle_max) + 1} r/min exceeds",
            "hob spindle maximum")
    assert program_count(run) == before


def test_a_finish_feed_edited_beyond_the_table_is_refused(run):
    """Reference §C: at m2 a finishing cut takes at most 1.5 mm per workpiece revolution (single-
    start hob). A runner's 2.0 (below the 3.0 roughing maximum the simulation holds every pass
    to) is refused as a new job's override of 2.0 is."""
    job = made_job(run, "--cuts", "2")
    params = one_value(run, "SELECT params FROM job WHERE id = %s", job)
    module_params = one_value(run, "SELECT module_params FROM job WHERE id = %s", job)
    finish = next(key for key, cut in module_params.items() if cut.get("cut_name") == "FINISH")
    table_speed = params["n0"] * params["z0"] / params["z2"]   # §B5: n2 = n0·z0/z2, r/min
    feed = round(2.0 * table_speed, 1)                          # mm/min for 2.0 mm/rev
    copy = runners_copy(run, job, module_params={finish: {**module_params[finish], "feed_axial": feed}})
    before = program_count(run)
    refused(run("instantiate", "--job", copy), f"job {copy}, module_params.{finish}.feed_axial",
            "1.50 mm/rev finishing maximum")
    assert program_count(run) == before


def test_a_legitimate_edit_still_makes_its_program(run):
    """A lower hob speed and a feed within the table, edited in SQL, are the shop's to choose. 20 mm/min
    at n0 200 is 20/(200/19) = 1.9 mm per workpiece rev: within §C and within the feed marks grade 7
    allows gear 42 (§B6: 1.9²·sin 20°/280 = 4.4 µm of 6.4)."""
    job = made_job(run)
    module_params = one_value(run, "SELECT module_params FROM job WHERE id = %s", job)
    single = next(key for key, cut in module_params.items() if cut["cut_on"])
    copy = runners_copy(run, job, params={"n0": 200}, module_params={single: {**module_params[single],
                                                                                "feed_axial": 20.0}})
    made = run("instantiate", "--job", copy)
    assert made.exit_code == 0, made.output
    assert "M3 S200" in made.stdout and "F20.0" in made.stdout


@pytest.mark.parametrize("target", [("--gear", "42"), ("--job", None), ("--jobs", None)])
def test_a_draft_with_out_is_refused(run, tmp_path, target):
    job = made_job(run)
    option, value = target
    given = value or (str(job) if option == "--job" else f"{job}-{job}")
    before, out = program_count(run), tmp_path / "nc"
    refused(run("instantiate", option, given, "--draft", "--out", out), "--draft", "never written to a file")
    assert program_count(run) == before and not out.exists()


def test_a_draft_with_the_machine_folder_of_the_config_file_is_refused(read_only_run, tmp_path):
    folder = tmp_path / "hobber"
    read_only_run.config.write_text(f'[machines.hobber-840d]\nout = "{folder}"\n')
    before = program_count(read_only_run)
    refused(read_only_run("instantiate", "--gear", 42, "--draft"), "--draft", str(folder))
    assert program_count(read_only_run) == before and not folder.exists()
    dry = read_only_run("instantiate", "--gear", 42, "--draft", "--dry-run")   # the folder is not a dry run's
    assert dry.exit_code == 0 and "%_N_GEAR42_MPF" in dry.stdout and not folder.exists()


def test_a_draft_alone_is_printed(run):
    made = run("instantiate", "--gear", 42, "--draft")
    assert made.exit_code == 0, made.output
    assert made.stdout.startswith("%_N_GEAR42_MPF") and "written to" not in made.stderr
