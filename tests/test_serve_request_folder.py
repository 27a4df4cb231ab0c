"""Programs asked for through a request folder (issue 32), as an 840D on a network share asks: it
writes `<stem>.REQ`, waits for `<stem>.RDY` with ISFILE, reads the file name in it and EXTCALLs that
file. The answer comes once, only for a complete request, with the program written whole under a
name carrying a hash of its bytes (PG<program id>_<sha256, 7 hex>.MPF,
docs/guide/serving-programs.md); a refusal is `<stem>.ERR` with the reason. Each test on a private
copy of the seeded database: answering stores and records."""
from __future__ import annotations

import hashlib
import json
import re

import psycopg
import pytest
from helpers.roles import logins
from psycopg import sql

from engine.errors import EngineError
from engine.plants.tables import ID_SEQUENCES
from engine.programs.config import Config
from engine.service.request_folder import RequestFolder


def stored_job(run, gear: int, machine: str = "hobber-840d") -> dict:
    made = run("instantiate", "--gear", gear, "--machine", machine, "--json")
    assert made.exit_code == 0, made.output
    return json.loads(made.stdout)


def requests(url: str) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT machine, via, client, asked_for, job_id, program_id, refusal FROM program_request "
                            "ORDER BY id").fetchall()


def answered(folder: RequestFolder) -> list:
    """Two looks: a request is taken once it is unchanged since the look before."""
    return folder.poll_once() + folder.poll_once()


def test_a_request_gets_the_program_whole_under_its_hash_then_the_answer(run, folders, tmp_path):
    made = stored_job(run, 42)
    out = tmp_path / "out"
    out.mkdir()
    assert run("instantiate", "--job", made["job_id"], "--out", f"{out}/").exit_code == 0
    written = (out / "GEAR42.MPF").read_bytes()
    program_id = int(written.split(b"; PROGRAM ")[1].split()[0])
    share = folders.root / "hobber-840d"
    (share / "HOB1.REQ").write_text(f"JOB {made['job_id']}\n")
    [answer] = answered(folders)
    name = f"PG{program_id}_{hashlib.sha256(written).hexdigest()[:7].upper()}.MPF"
    # the answer names the program, then the request it answers (the control compares it with its own)
    assert (share / "HOB1.RDY").read_text() == f"{name}\nJOB {made['job_id']}\n" and answer.program_file == name
    assert (share / name).read_bytes() == written   # the file instantiate --job writes, byte for byte
    assert sorted(path.name for path in share.iterdir()) == ["HOB1.DONE", "HOB1.RDY", name]   # no temporary left
    assert requests(run.url) == [("hobber-840d", "folder", "hobber-840d/HOB1.REQ", f"JOB {made['job_id']}",
                                  made["job_id"], program_id, None)]


# an 840D program name (docs/reference/hobbing.md §A1): two letters (or _ and a letter) first,
# letters, digits and _, at most 24 characters; EXTCALL then takes the extension
PROGRAM_NAME_840D = re.compile(r"(?:[A-Z]{2}|_[A-Z])[A-Z0-9_]{0,22}\.MPF")


def test_a_plants_program_file_is_an_840d_program_name(run, folders):
    """Plant 9999 of issue 33 makes ids from 9999·10^10 on: 14 digits. PRG<id>_<8 hex> was 26
    characters before .MPF there, beyond the 840D's 24 (the review of issue 32)."""
    first = 9999 * 10**10
    with psycopg.connect(run.url) as conn:   # plant 9999, its id sequences in its range (engine plant subscribe)
        conn.execute("INSERT INTO plant_identity (number) VALUES (9999)")
        for sequence in ID_SEQUENCES:
            conn.execute(sql.SQL("ALTER SEQUENCE {} RESTART WITH {}").format(sql.Identifier(sequence),
                                                                             sql.Literal(first)))
    made = stored_job(run, 42)
    share = folders.root / "hobber-840d"
    (share / "BIG.REQ").write_text(f"JOB {made['job_id']}\n")
    [answer] = answered(folders)
    data = (share / answer.program_file).read_bytes()
    program_id = int(data.split(b"; PROGRAM ")[1].split()[0])
    assert program_id >= first and len(str(program_id)) == 14
    assert answer.program_file == f"PG{program_id}_{hashlib.sha256(data).hexdigest()[:7].upper()}.MPF"
    assert PROGRAM_NAME_840D.fullmatch(answer.program_file), answer.program_file


def test_a_half_written_request_waits_until_complete_and_is_answered_once(run, folders):
    made = stored_job(run, 42, "hobber-fanuc")
    share = folders.root / "hobber-fanuc"
    (share / "R7.REQ").write_text("GEAR 4")   # the control still writing: no new line yet
    assert answered(folders) == [] and not (share / "R7.RDY").exists()
    with open(share / "R7.REQ", "a") as request:
        request.write("2\n")
    assert folders.poll_once() == []   # it changed since the last look: once more
    [answer] = folders.poll_once()
    assert answer.refusal is None and (share / answer.program_file).read_bytes().startswith(b"%\nO1042")
    assert answered(folders) == [] and [row[4] for row in requests(run.url)] == [made["job_id"]]


def test_another_machines_job_is_refused_with_an_err_file_and_the_next_request_answered(run, folders):
    fanuc = stored_job(run, 42, "hobber-fanuc")
    share = folders.root / "hobber-840d"
    (share / "X.REQ").write_text(f"JOB {fanuc['job_id']}\n")
    [answer] = answered(folders)
    reason, answered_request = (share / "X.ERR").read_text().split("\n", 1)
    assert answered_request == f"JOB {fanuc['job_id']}\n"
    assert f"job {fanuc['job_id']} is a job of machine hobber-fanuc, not of hobber-840d" in reason
    assert not (share / "X.RDY").exists() and not list(share.glob("*.MPF")) and (share / "X.DONE").exists()
    assert requests(run.url) == [("hobber-840d", "folder", "hobber-840d/X.REQ", f"JOB {fanuc['job_id']}", None, None,
                                  reason.strip())]
    own = stored_job(run, 43)   # the same connection answers the next request: the refusal left it usable
    (share / "Y.REQ").write_text(f"JOB {own['job_id']}\n")
    [answer] = answered(folders)
    assert answer.refusal is None and (share / "Y.RDY").read_text() == f"{answer.program_file}\nJOB {own['job_id']}\n"


def test_a_stale_answer_is_replaced_and_what_is_not_a_request_is_refused(run, folders):
    share = folders.root / "hobber-840d"
    (share / "A.RDY").write_text("PG1_0000000.MPF\n")   # an earlier request's answer, left there
    (share / "A.REQ").write_text("PLEASE SEND\n")
    answered(folders)
    assert not (share / "A.RDY").exists() and "names no program" in (share / "A.ERR").read_text()
    [(_, _, _, asked, job_id, program_id, refusal)] = requests(run.url)   # recorded as every refusal is
    assert (asked, job_id, program_id) == ("PLEASE SEND", None, None) and "names no program" in refusal


LONG_STEM = "HOB_REQUEST_FOR_GEAR_42_X"   # 25 characters, one more than a request's stem may have
assert len(LONG_STEM) == 25


@pytest.mark.parametrize("stem, why", [("bad-name", "holds '-'"), (LONG_STEM, "has 25 characters"),
                                       ("two words", "holds ' '")])
def test_a_request_whose_stem_breaks_the_rule_is_answered_err_recorded_and_logged(run, folders, caplog, stem, why):
    """The review of issue 32: bad-name.REQ was left alone, no answer, no record, no log, and the
    control timed out. It gets <stem>.ERR with the rule (the guide's: 1 to 24 letters, digits, _)."""
    made = stored_job(run, 42)
    share = folders.root / "hobber-840d"
    (share / f"{stem}.REQ").write_text(f"JOB {made['job_id']}\n")
    with caplog.at_level("WARNING", logger="engine.service.request_folder"):
        [answer] = answered(folders)
        assert answered(folders) == []   # answered once
    err = (share / f"{stem}.ERR").read_text().splitlines()
    assert err[0].startswith(f"request file '{stem}.REQ' refused: its stem {why}")
    assert "1 to 24 letters, digits and _" in err[0] and err[1:] == [f"JOB {made['job_id']}"]
    assert answer.refusal == err[0] and answer.program_file is None
    assert sorted(path.name for path in share.iterdir()) == sorted([f"{stem}.DONE", f"{stem}.ERR"])   # nothing sent
    assert requests(run.url) == [("hobber-840d", "folder", f"hobber-840d/{stem}.REQ", f"JOB {made['job_id']}", None,
                                  None, err[0])]
    assert any(err[0] in record.getMessage() for record in caplog.records)


def test_a_request_name_too_long_to_claim_is_said_once_in_the_log_and_a_link_is_never_answered(run, folders, caplog,
                                                                                              tmp_path):
    """A name of 255 bytes cannot be renamed .DONE (ext4's limit): it is said in the log once, not at
    every look; a link named like a bad request is neither read nor answered."""
    share = folders.root / "hobber-840d"
    (share / f"{'A' * 251}.REQ").write_text("JOB 1\n")
    (tmp_path / "target.txt").write_text("JOB 1\n")
    (share / "bad-link.REQ").symlink_to(tmp_path / "target.txt")
    with caplog.at_level("WARNING", logger="engine.service.request_folder"):
        assert answered(folders) + answered(folders) == []
    assert sum("too long to claim" in record.getMessage() for record in caplog.records) == 1
    assert sorted(path.name for path in share.iterdir()) == sorted([f"{'A' * 251}.REQ", "bad-link.REQ"])
    assert requests(run.url) == []


def test_a_link_is_never_read_as_a_request(run, folders, tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("JOB 1 of the payroll\n")
    (folders.root / "hobber-840d" / "L.REQ").symlink_to(secret)
    assert answered(folders) == [] and sorted(path.name for path in (folders.root / "hobber-840d").iterdir()) == \
        ["L.REQ"]


def test_a_machine_that_does_not_exist_is_refused(read_only_database_url, tmp_path):
    with pytest.raises(EngineError, match="machine hobber-9 of the request folders does not exist"):
        RequestFolder(tmp_path, ["hobber-9"], read_only_database_url, Config())


def test_the_service_needs_only_a_runners_login(run, server_url, tmp_path):
    """engine serve connects as a login in engine_runner (design §10): it stores the program again
    if need be and records the request, which names that login."""
    made = stored_job(run, 42)
    with psycopg.connect(run.url) as conn:   # the job edited since: the program is made again, as the runner
        conn.execute("UPDATE job SET params = params || '{\"program_name\": \"SHAFT_7\"}' WHERE id = %s",
                     (made["job_id"],))
    with logins(server_url) as create:
        runner = create("engine_runner")
        folder = RequestFolder(tmp_path, ["hobber-840d"], runner.url(run.url), Config())
        try:
            (tmp_path / "hobber-840d" / "R.REQ").write_text(f"SHAFT_7_J{made['job_id']}.MPF\n")
            [answer] = answered(folder)
        finally:
            folder.close()
    assert answer.refusal is None and answer.program_file.startswith("PG")
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT requested_by, program_id > %s FROM program_request",
                            (made["program_id"],)).fetchall() == [(runner.name, True)]
