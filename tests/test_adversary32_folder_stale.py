"""Adversary of issue 32: a request folder must never answer one request with another's program.

An 840D's WRITE appends a line to a file. A request left unanswered (engine serve stopped, the control
gave up after its 60 tries) and the control then asking for another job appends that job to the old
request: `JOB 17` then `JOB 18`. The engine answered the first line, so the control, waiting for
`.RDY`, called job 17's program for job 18. And a request written again while the engine was answering
it was renamed `.DONE` unanswered, while the `.RDY` naming the first one's program was taken for it.
Each test on a private copy of the seeded database."""
import json
import threading

import psycopg


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


def test_a_request_written_again_while_answered_is_answered_itself(run, folders):
    first, second = job_of(run, 42), job_of(run, 43)
    share = folders.root / "hobber-840d"
    (share / "HOB1.REQ").write_text(f"JOB {first['job_id']}\n")
    assert folders.poll_once() == []   # seen once: taken at the next look
    with psycopg.connect(run.url) as holder:   # the answer's record waits until the request is written again
        holder.execute("LOCK TABLE program_request IN EXCLUSIVE MODE")
        polled: list = []
        answering = threading.Thread(target=lambda: polled.extend(folders.poll_once()))
        answering.start()
        while not holder.execute("SELECT count(*) FROM pg_locks WHERE NOT granted AND relation = "
                                 "'program_request'::regclass").fetchone()[0]:
            pass
        (share / "HOB1.REQ").write_text(f"JOB {second['job_id']}\n")   # the control asks again, for job 43
    answering.join(timeout=120)
    assert not (share / "HOB1.RDY").exists()   # job 42's program is not the answer to the request for 43
    answers = folders.poll_once() + folders.poll_once()
    assert [answer.request for answer in answers] == ["HOB1.REQ"]
    assert (share / answers[0].program_file).read_bytes().count(f"; PROGRAM {second['program_id']} ".encode()) == 1
    assert (share / "HOB1.RDY").read_text() == f"{answers[0].program_file}\nJOB {second['job_id']}\n"
