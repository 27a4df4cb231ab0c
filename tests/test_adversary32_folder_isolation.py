"""Adversary of issue 32: one machine's request folder holding what cannot be answered (the answer's
name taken by a folder) must not stop the others: before, the error left poll_once, so every request
after it, of every machine, waited forever."""
import json


def job_of(run, machine: str) -> int:
    made = run("instantiate", "--gear", 42, "--machine", machine, "--json")
    assert made.exit_code == 0, made.output
    return json.loads(made.stdout)["job_id"]


def test_a_request_that_cannot_be_answered_does_not_stop_the_others(run, folders):
    share840, fanuc = folders.root / "hobber-840d", folders.root / "hobber-fanuc"
    (share840 / "A.REQ").write_text(f"JOB {job_of(run, 'hobber-840d')}\n")
    (share840 / "A.RDY").mkdir()   # its answer's name taken by a folder: it cannot be answered
    (share840 / "B.REQ").write_text(f"JOB {job_of(run, 'hobber-840d')}\n")
    (fanuc / "C.REQ").write_text(f"JOB {job_of(run, 'hobber-fanuc')}\n")
    answers = folders.poll_once() + folders.poll_once()
    assert sorted(answer.request for answer in answers) == ["B.REQ", "C.REQ"]
    assert (share840 / "B.RDY").is_file() and (fanuc / "C.RDY").is_file()
    assert (share840 / "A.REQ").exists()   # left as it is, looked at again next time

