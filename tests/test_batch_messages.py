"""What a refused batch says in its first line (issue 16): counted in plain English, and a stored
job that does not exist is looked up with `engine jobs list`."""
from __future__ import annotations

import pytest
from helpers.batches import spoil


@pytest.mark.parametrize("skip_bad", [[], ["--skip-bad"]], ids=["", "--skip-bad"])
def test_a_batch_of_bad_gears_only_says_every_one_of_them_is_bad(run, skip_bad):
    spoil(run.url)
    refused = run("instantiate", "--gears", "44-46", *skip_bad)
    assert refused.exit_code == 1
    assert refused.stderr.splitlines()[0] == "error: every one of the 3 gears of the batch is bad, nothing stored:"


def test_a_batch_of_one_bad_gear_says_the_one_gear_is_bad(run):
    spoil(run.url)
    refused = run("instantiate", "--gears", "44-44")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert refused.stderr.startswith("error: gear 44") and refused.stderr.rstrip().endswith(
        "nothing stored (the one gear of the batch is bad)")


def test_a_job_that_does_not_exist_points_at_the_jobs_list(read_only_run):
    refused = read_only_run("instantiate", "--job", 999999)
    assert refused.exit_code == 1
    assert refused.stderr == "error: job 999999 does not exist; `engine jobs list` shows what does\n"
