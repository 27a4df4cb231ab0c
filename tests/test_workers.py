"""Batch planning across cores (issue 12): --workers N stores exactly what one process stores,
all programs in one transaction, and a bad gear in a worker stores nothing (issue 16: every bad
gear is named)."""
import json

import psycopg
import pytest
from helpers.lineage_text import LINES_ID_MASKED


def stored_programs(url):
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT p.name, " + LINES_ID_MASKED + ", p.row_ids, p.trace, j.params, j.module_params, "
                            "j.cutting FROM program p JOIN job j ON j.id = p.job_id ORDER BY p.id").fetchall()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_two_workers_store_what_one_process_stores(run):
    one = run("instantiate", "--gears", "42-54", "--json")
    first = stored_programs(run.url)
    two = run("instantiate", "--gears", "42-54", "--workers", "2", "--json")
    both = stored_programs(run.url)
    assert one.exit_code == two.exit_code == 0
    assert json.loads(two.stdout)["programs"] == json.loads(one.stdout)["programs"] == len(first) >= 9
    assert both[len(first):] == first                  # the same programs, traces and jobs, in gear order


def test_a_failing_gear_in_a_worker_stops_the_batch_and_stores_nothing(run):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET gear_class = NULL WHERE id = 46")
    refused = run("instantiate", "--gears", "42-54", "--workers", "2")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert "gear 46 has no gear class" in refused.stderr and "nothing stored" in refused.stderr
    assert stored_programs(run.url) == []


def test_workers_are_for_batches(read_only_run):
    refused = read_only_run("instantiate", "--gear", "42", "--workers", "2")
    assert refused.exit_code == 1 and "--workers plans a batch" in refused.stderr


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_class_refused_in_a_worker_names_each_of_its_gears_and_nothing_is_stored(run):
    # the Planner remembers the refusal: a worker never reads the database it shares with the parent
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET gear_class = 'turning_iso' WHERE id IN (45, 46, 47)")
    refused = run("instantiate", "--gears", "42-54", "--workers", "2")
    assert refused.exit_code == 1 and refused.stderr.startswith("error: 3 of 10 gears of the batch are bad")
    for gear in (45, 46, 47):
        assert f"\n  gear {gear}: class 'turning_iso' is a turning class" in refused.stderr
    assert stored_programs(run.url) == []


def test_jobs_of_one_gear_are_not_written_over_each_other(run, tmp_path):
    assert run("instantiate", "--gears", "42-43").exit_code == 0
    assert run("instantiate", "--gear", "42").exit_code == 0
    before = stored_programs(run.url)
    with psycopg.connect(run.url) as conn:
        jobs = [row[0] for row in conn.execute("SELECT id FROM job ORDER BY id")]
    refused = run("instantiate", "--jobs", f"{jobs[0]}-{jobs[-1]}", "--out", tmp_path / "programs")
    assert refused.exit_code == 1 and "programs of this batch are named GEAR42" in refused.stderr
    assert stored_programs(run.url) == before and not (tmp_path / "programs").exists()


@pytest.mark.slow   # two batches of 13 gears
def test_two_workers_skipping_a_bad_gear_store_the_good_ones_one_process_stores(run):
    # issue 28: a batch planned in workers is stored slice by slice as the slices come back
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET gear_class = NULL WHERE id = 50")
    one = run("instantiate", "--gears", "42-54", "--skip-bad", "--json")
    first = stored_programs(run.url)
    two = run("instantiate", "--gears", "42-54", "--skip-bad", "--workers", "2", "--json")
    assert one.exit_code == two.exit_code == 0
    assert json.loads(two.stdout)["skipped"] == json.loads(one.stdout)["skipped"]
    assert any("gear 50" in reason for reason in json.loads(two.stdout)["skipped"])
    assert stored_programs(run.url)[len(first):] == first


def test_a_file_refused_after_the_workers_stored_their_slices_leaves_nothing_stored(run, tmp_path):
    # the slices stored while the workers planned are in the batch's one transaction: a file that
    # may not be replaced, found when every gear is planned, rolls all of them back
    folder = tmp_path / "programs"
    folder.mkdir()
    (folder / "GEAR54.MPF").write_text("; the operator's own file\n")
    refused = run("instantiate", "--gears", "42-54", "--workers", "2", "--out", folder)
    assert refused.exit_code == 1 and "GEAR54.MPF" in refused.stderr and "nothing stored" in refused.stderr
    assert stored_programs(run.url) == []
    assert sorted(path.name for path in folder.iterdir()) == ["GEAR54.MPF"]
