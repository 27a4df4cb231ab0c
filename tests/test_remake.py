"""Stored jobs made again in a batch (`engine instantiate --jobs FIRST-LAST`, issue 12): the
programs of their stored parameters, all stored in one transaction or none."""
import json

import psycopg
import pytest
from helpers.lineage_text import LINES_ID_MASKED


def programs(url, where=""):
    with psycopg.connect(url) as conn:
        return conn.execute(f"SELECT job_id, {LINES_ID_MASKED}, row_ids, trace FROM program p {where} "
                            "ORDER BY id").fetchall()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_jobs_made_again_give_their_programs_back(run):
    assert run("instantiate", "--gears", "42-54").exit_code == 0
    first = programs(run.url)
    jobs = [job for job, *_ in first]
    made = run("instantiate", "--jobs", f"{min(jobs)}-{max(jobs)}", "--json")
    assert made.exit_code == 0 and json.loads(made.stdout)["programs"] == len(first)
    assert programs(run.url)[len(first):] == first      # same job, lines, rows and trace, in job order


def test_a_job_edited_in_sql_is_made_with_its_new_parameters(run):
    assert run("instantiate", "--gears", "42-43").exit_code == 0
    job = programs(run.url)[0][0]
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE job SET params = jsonb_set(params, '{n0}', '250') WHERE id = %s", (job,))
    assert run("instantiate", "--jobs", f"{job}-{job}").exit_code == 0
    assert "M3 S250" in programs(run.url, f"WHERE job_id = {job}")[-1][1]


def test_a_hobbing_job_renamed_to_another_gears_program_is_refused(run):
    """GEAR43's job renamed GEAR44 in SQL would write GEAR44.MPF, replacing gear 44's program on
    the control: refused in one line, nothing stored."""
    assert run("instantiate", "--gears", "43-44").exit_code == 0
    job = programs(run.url)[0][0]
    with psycopg.connect(run.url) as conn:
        conn.execute("""UPDATE job SET params = jsonb_set(params, '{program_name}', '"GEAR44"') WHERE id = %s""",
                     (job,))
    before = len(programs(run.url))
    refused = run("instantiate", "--job", job)
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert f"program name 'GEAR44' of job {job} (gear 43) is the name of gear 44's program" in refused.stderr
    assert len(programs(run.url)) == before


def test_two_gears_jobs_renamed_to_one_part_number_are_refused(run):
    """A part number may replace GEAR<id>, but two gears' programs under one name (PARTX) would
    overwrite each other on the control: the second is refused, nothing stored."""
    assert run("instantiate", "--gears", "43-44").exit_code == 0
    first, second = [job for job, *_ in programs(run.url)][:2]
    with psycopg.connect(run.url) as conn:
        for job in (first, second):
            conn.execute("""UPDATE job SET params = jsonb_set(params, '{program_name}', '"PARTX"') WHERE id = %s""",
                         (job,))
    before = len(programs(run.url))
    refused = run("instantiate", "--job", second)
    assert refused.exit_code == 1 and "program name 'PARTX'" in refused.stderr and "gear 43's program" in refused.stderr
    assert len(programs(run.url)) == before


def test_a_failing_job_stops_the_batch_and_stores_nothing(run):
    assert run("instantiate", "--gears", "42-45").exit_code == 0
    jobs = [job for job, *_ in programs(run.url)]
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE job SET params = params - 'z2' WHERE id = %s", (jobs[1],))
    refused = run("instantiate", "--jobs", f"{min(jobs)}-{max(jobs)}")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert f"job {jobs[1]}: " in refused.stderr and "unknown parameter 'z2'" in refused.stderr
    assert len(programs(run.url)) == len(jobs)


def test_a_choice_for_a_new_job_is_refused_for_stored_jobs(run):
    made = run("instantiate", "--gear", "42", "--json")
    job = json.loads(made.stdout)["job_id"]
    for args in (("--job", job, "--no-coolant"), ("--jobs", f"{job}-{job}", "--hob-speed", "300")):
        refused = run("instantiate", *args)
        assert refused.exit_code == 1 and "applies to a new job" in refused.stderr and "job.params" in refused.stderr
    assert run("instantiate", "--job", job).exit_code == 0


def test_json_is_one_object_on_one_line(run):   # design notes §9
    made = run("instantiate", "--gear", "42", "--json")
    assert made.stdout.count("\n") == 1 and json.loads(made.stdout)["lines"] > 20
