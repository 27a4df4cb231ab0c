"""A gear or job deleted by another session while its program is made (issue 16): the command
says so in one line, exit 1, and stores nothing; it is not a foreign-key violation (exit 2)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import psycopg
import pytest

GEAR = ("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material, hardness, quality_grade, "
        "quantity) VALUES (%s, 'spur', 2, %s, 0, 20, '40Cr', 250, 7, 50)")


def add_gears(url: str, *ids: int) -> None:
    with psycopg.connect(url) as conn:
        for gear_id in ids:
            conn.execute(GEAR, (gear_id, 29 + gear_id % 7))


def counts(url: str) -> tuple:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()


def engine_while_deleting(url: str, delete: str, *args) -> subprocess.CompletedProcess:
    """`engine ARGS` run while another session's `delete` is uncommitted; the delete commits once
    the command waits for it."""
    deleter = psycopg.connect(url)
    deleter.execute(delete)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parent.parent),
                                                        os.environ.get("PYTHONPATH", "")]), "ENGINE_CONFIG": ""}
    making = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", url, *map(str, args)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    with psycopg.connect(url, autocommit=True) as watcher:
        while making.poll() is None and not watcher.execute(
                "SELECT count(*) FROM pg_stat_activity WHERE datname = current_database() "
                "AND wait_event_type = 'Lock'").fetchone()[0]:
            time.sleep(0.05)
    deleter.commit()
    deleter.close()
    stdout, stderr = making.communicate(timeout=120)
    return subprocess.CompletedProcess(args, making.returncode, stdout, stderr)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_job_deleted_while_it_is_made_again_is_said_in_one_line(run):
    url = run.url
    add_gears(url, 91511)
    made = run("instantiate", "--gear", 91511)
    assert made.exit_code == 0, made.output
    with psycopg.connect(url) as conn:
        job_id = conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params, cutting) "
                              "SELECT gear_id, gear_class, machine, hob_id, params, module_params, cutting FROM job "
                              "WHERE gear_id = 91511 RETURNING id").fetchone()[0]   # a copy, no program yet
    before = counts(url)
    result = engine_while_deleting(url, f"DELETE FROM job WHERE id = {job_id}", "instantiate", "--job", job_id)
    assert result.returncode == 1, result.stderr
    assert result.stderr == f"error: job {job_id} was deleted while its program was made; nothing stored\n"
    assert counts(url) == (before[0] - 1, before[1])   # the deleted job, nothing stored


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_gear_of_a_batch_deleted_meanwhile_is_named_and_nothing_is_stored(fresh_database_url):
    url = fresh_database_url
    add_gears(url, 91521, 91522, 91523)
    before = counts(url)
    result = engine_while_deleting(url, "DELETE FROM gear WHERE id = 91522", "instantiate", "--gears", "91521-91523")
    assert result.returncode == 1, result.stderr
    assert result.stderr.startswith("error: gear 91522 was deleted") and result.stderr.count("\n") == 1
    assert counts(url) == before


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_hob_deleted_while_a_program_is_made_with_it_is_said_in_one_line(run):
    url = run.url
    add_gears(url, 91531)
    matched = run("hobs", "match", "--gear", 91531, "--json")
    assert matched.exit_code == 0, matched.output
    hob_id = json.loads(matched.stdout)["hob_id"]
    before = counts(url)
    result = engine_while_deleting(url, f"DELETE FROM hob WHERE id = '{hob_id}'", "instantiate", "--gear", 91531)
    assert result.returncode == 1, result.stderr
    assert result.stderr == f"error: hob {hob_id} was deleted while its program was made; nothing stored\n"
    assert counts(url) == before


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_gear_deleted_while_its_program_is_made_is_bad_input_not_a_bug(fresh_database_url):
    """`engine gears delete 91501 --yes` committing while `instantiate --gear 91501` plans: the
    gear is gone, which is said in one line (exit 1), not ForeignKeyViolation with exit 2."""
    import os
    import subprocess
    import sys
    import time

    url = fresh_database_url
    with psycopg.connect(url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material, hardness, "
                     "quality_grade, quantity) VALUES (91501, 'spur', 2, 31, 0, 20, '40Cr', 250, 7, 50)")
    deleter = psycopg.connect(url)
    deleter.execute("DELETE FROM gear WHERE id = 91501")   # the delete, not yet committed
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parent.parent),
                                                        os.environ.get("PYTHONPATH", "")]), "ENGINE_CONFIG": ""}
    making = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", url, "instantiate", "--gear",
                               "91501"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    with psycopg.connect(url, autocommit=True) as watcher:
        while making.poll() is None and not watcher.execute(
                "SELECT count(*) FROM pg_stat_activity WHERE datname = current_database() "
                "AND wait_event_type = 'Lock'").fetchone()[0]:
            time.sleep(0.05)   # until instantiate waits for the delete's transaction
    deleter.commit()
    deleter.close()
    stdout, stderr = making.communicate(timeout=120)
    assert making.returncode == 1, stderr
    assert stderr.startswith("error: ") and stderr.count("\n") == 1 and "91501" in stderr
