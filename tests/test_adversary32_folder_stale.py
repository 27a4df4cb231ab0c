"""Adversary of issue 32: a request folder must never answer one request with another's program.

An 840D's WRITE appends a line to a file. A request left unanswered (engine serve stopped, the control
gave up after its 60 tries) and the control then asking for another job appends that job to the old
request: `JOB 17` then `JOB 18`. The engine answered the first line, so the control, waiting for
`.RDY`, called job 17's program for job 18.
Each test on a private copy of the seeded database."""
import json

import pytest

from engine.programs.config import Config
from engine.service.request_folder import RequestFolder


@pytest.fixture
def folders(run, tmp_path):
    root = tmp_path / "share"
    root.mkdir()
    folder = RequestFolder(root, ["hobber-840d"], run.url, Config())
    yield folder
    folder.close()


def job_of(run, gear: int) -> dict:
    made = run("instantiate", "--gear", gear, "--machine", "hobber-840d", "--json")
    assert made.exit_code == 0, made.output
    return json.loads(made.stdout)


def test_a_request_of_two_lines_is_refused_not_answered_by_its_first(run, folders):
    first, second = job_of(run, 42)["job_id"], job_of(run, 43)["job_id"]
    share = folders.root / "hobber-840d"
    (share / "HOB1.REQ").write_text(f"JOB {first}\nJOB {second}\n")   # WRITE appended to an old request
    [answer] = folders.poll_once() + folders.poll_once()
    assert answer.program_file is None and not (share / "HOB1.RDY").exists()
    assert "2 lines" in (share / "HOB1.ERR").read_text()

