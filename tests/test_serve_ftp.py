"""Programs fetched by FTP (issue 32), as a control or a DNC client fetches them: a real server on an
ephemeral 127.0.0.1 port, Python's ftplib as the client, a real PostgreSQL. Each machine logs in with
its own secret and sees only its own jobs of released classes; RETR proves, stores and records, and
sends the bytes `engine instantiate --job J --out DIR/` writes; what cannot be proved is a 550 carrying
the reason, recorded; nothing can be written. The names a machine sees follow the scheme of
docs/guide/serving-programs.md: the program name, _J, the job id, .MPF."""
from __future__ import annotations

import ftplib
import io
import json
import shutil
import subprocess
import threading
from pathlib import Path

import psycopg
import pytest
from helpers.lineage_text import id_masked
from psycopg import sql
from psycopg.conninfo import make_conninfo

from engine.errors import EngineError
from engine.programs.config import load_config
from engine.programs.instantiate import instantiate_gear
from engine.service.ftp import start_ftp_server

SECRETS = {"hobber-840d": "hob-840d-secret", "hobber-fanuc": "fanuc-secret"}
CONFIG = """
[machines.hobber-840d]
ftp_secret_env = "TEST_FTP_SECRET_840D"
"""
# the 840D's secret through the variable its table names; the Fanuc's through the default variable
ENVIRONMENT = {"TEST_FTP_SECRET_840D": SECRETS["hobber-840d"],
               "ENGINE_FTP_SECRET_HOBBER_FANUC": SECRETS["hobber-fanuc"]}
NC_PART = "%_N_NC_PART_MPF\n;$PATH=/_N_MPF_DIR\nG90 G71 G94\nM30\n"


def config_file(folder: Path, text: str = CONFIG):
    path = folder / "config.toml"
    path.write_text(text)
    return load_config(path, named=True)


def login(port: int, machine: str, secret: str | None = None) -> ftplib.FTP:
    client = ftplib.FTP()
    client.connect("127.0.0.1", port, timeout=60)
    client.login(machine, SECRETS[machine] if secret is None else secret)
    return client


def fetched(port: int, machine: str, name: str) -> bytes:
    client = login(port, machine)
    data = io.BytesIO()
    client.retrbinary(f"RETR {name}", data.write)
    client.quit()
    return data.getvalue()


def refusal_of(port: int, machine: str, command: str) -> str:
    client = login(port, machine)
    with pytest.raises(ftplib.error_perm) as refused:
        client.sendcmd(command) if not command.startswith("RETR") else client.retrbinary(command, lambda _: None)
    client.quit()
    return str(refused.value)


def requests(url: str) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT machine, via, client, asked_for, job_id, program_id, refusal FROM program_request "
                            "ORDER BY id").fetchall()


def draft_only_job(run, tmp_path: Path) -> int:
    """A job of a class import-nc made, which has only a draft (no release)."""
    (tmp_path / "part.mpf").write_text(NC_PART)
    assert run("import-nc", tmp_path / "part.mpf", "--class", "nc_part").exit_code == 0
    with psycopg.connect(run.url) as conn:
        return conn.execute("INSERT INTO job (gear_class, machine, params) VALUES ('nc_part', 'hobber-840d', "
                            "'{\"program_name\": \"NC_PART\"}') RETURNING id").fetchone()[0]


@pytest.fixture
def secrets(monkeypatch):
    for name, value in ENVIRONMENT.items():
        monkeypatch.setenv(name, value)


def stored_job(run, gear: int, machine: str = "hobber-840d") -> dict:
    made = run("instantiate", "--gear", gear, "--machine", machine, "--json")
    assert made.exit_code == 0, made.output
    return json.loads(made.stdout)


@pytest.fixture
def serving(run, secrets, tmp_path):
    """The FTP server on a private copy of the seeded database; yields its port."""
    service = start_ftp_server(run.url, config_file(tmp_path))
    yield service.port
    service.close()


# --- one database for the tests that only list and are refused (READ ONLY once its jobs are made) ---

@pytest.fixture(scope="module")
def listed(server_url, database_pool, _seeded_copies, tmp_path_factory):
    """Jobs of gears 42 and 43 on the 840D, of gear 42 on the Fanuc, and a draft-only class's job on
    the 840D; then the database is made READ ONLY and the server started on it."""
    name = database_pool.take(_seeded_copies)
    url = make_conninfo(server_url, dbname=name)
    with psycopg.connect(url) as conn:
        jobs = {key: instantiate_gear(conn, gear, machine=machine).job_id
                for key, (gear, machine) in {"a": (42, "hobber-840d"), "b": (43, "hobber-840d"),
                                             "c": (42, "hobber-fanuc")}.items()}
        conn.execute("INSERT INTO gear_class (name, parent) VALUES ('nc_part', NULL)")
        jobs["draft"] = conn.execute("INSERT INTO job (gear_class, machine, params) VALUES ('nc_part', 'hobber-840d', "
                                     "'{\"program_name\": \"NC_PART\"}') RETURNING id").fetchone()[0]
    with psycopg.connect(server_url, autocommit=True) as admin:
        admin.execute(sql.SQL("ALTER DATABASE {} SET default_transaction_read_only = on").format(sql.Identifier(name)))
    with pytest.MonkeyPatch.context() as patch:
        for variable, value in ENVIRONMENT.items():
            patch.setenv(variable, value)
        service = start_ftp_server(url, config_file(tmp_path_factory.mktemp("ftp")), failed_login_delay=0.05)
        yield service.port, jobs
        service.close()
    database_pool.give_back(name)


def test_each_machine_lists_only_its_jobs_of_released_classes(listed):
    port, jobs = listed
    client = login(port, "hobber-840d")
    assert sorted(client.nlst()) == [f"GEAR42_J{jobs['a']}.MPF", f"GEAR43_J{jobs['b']}.MPF"]
    lines: list[str] = []
    client.retrlines("LIST", lines.append)
    assert [line.split()[-1] for line in lines] == [f"GEAR42_J{jobs['a']}.MPF", f"GEAR43_J{jobs['b']}.MPF"]
    assert all(line.startswith("-r--r--r--") for line in lines)   # files, nobody's to write
    assert client.sendcmd(f"MDTM GEAR42_J{jobs['a']}.MPF").startswith("213 20")
    client.quit()
    assert login(port, "hobber-fanuc").nlst() == [f"GEAR42_J{jobs['c']}.MPF"]   # the draft-only job nowhere


@pytest.mark.parametrize("machine, secret", [("hobber-840d", "wrong"), ("hobber-840d", ""),
                                             ("anonymous", "guest@example.com"), ("lathe-iso", "anything")])
def test_a_wrong_secret_anonymous_and_a_machine_without_a_secret_cannot_log_in(listed, machine, secret):
    client = ftplib.FTP()
    client.connect("127.0.0.1", listed[0], timeout=60)
    with pytest.raises(ftplib.error_perm, match="^530"):
        client.login(machine, secret)
    client.close()


@pytest.mark.parametrize("command", ["DELE GEAR42_J1.MPF", "MKD PROGRAMS", "RMD PROGRAMS", "RNFR GEAR42_J1.MPF",
                                     "SITE CHMOD 777 GEAR42_J1.MPF", "MFMT 20260101000000 GEAR42_J1.MPF"])
def test_every_write_is_refused(listed, command):
    said = refusal_of(listed[0], "hobber-840d", command)
    assert said.startswith("550") and "refused" in said and "only sends programs" in said


def test_stor_and_appe_are_refused_and_nothing_appears(listed):
    port, jobs = listed
    client = login(port, "hobber-840d")
    for command in ("STOR", "APPE"):
        with pytest.raises(ftplib.error_perm, match=f"^550 {command} refused"):
            client.storbinary(f"{command} GEAR99_J1.MPF", io.BytesIO(b"M30\n"))
    assert sorted(client.nlst()) == [f"GEAR42_J{jobs['a']}.MPF", f"GEAR43_J{jobs['b']}.MPF"]
    client.quit()


def test_size_resuming_and_other_folders_are_refused(listed):
    port, jobs = listed
    # 502 "not implemented" (RFC 959), never 550, which clients take for "no such file"
    assert refusal_of(port, "hobber-840d", f"SIZE GEAR42_J{jobs['a']}.MPF").startswith("502 SIZE is not offered")
    assert refusal_of(port, "hobber-840d", "CWD /other").startswith("550")
    for command in ("REST 100", "MLSD", "MLST GEAR42_J1.MPF"):   # a program is sent whole, listed by LIST
        assert refusal_of(port, "hobber-840d", command).startswith("500")
    client = login(port, "hobber-840d")
    assert not {"REST", "MLST", "SIZE"} & set(client.sendcmd("FEAT").split())
    client.quit()


def test_the_config_file_never_holds_a_secret(tmp_path):
    with pytest.raises(EngineError, match="ftp_secret_env") as refused:
        config_file(tmp_path, '[machines.hobber-840d]\nftp_secret = "hunter2-plain"\n')
    assert "hunter2-plain" not in str(refused.value) and "line 2" in str(refused.value)


# --- fetching: each test on a private copy, as RETR stores and records ----------------------------------

def test_retr_proves_records_and_sends_the_same_program_twice(run, serving):
    made = stored_job(run, 42)
    name = f"GEAR42_J{made['job_id']}.MPF"
    first, second = fetched(serving, "hobber-840d", name), fetched(serving, "hobber-840d", name)
    assert first == second   # the stored program, proved again: its lineage line too
    assert f"; PROGRAM {made['program_id']} TEMPLATE spur".encode() in first
    sent = ("hobber-840d", "ftp", "127.0.0.1", name, made["job_id"], made["program_id"], None)
    assert requests(run.url) == [sent, sent]


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl is not installed")
def test_curl_fetches_a_program_though_it_asks_its_size_first(run, serving, tmp_path):
    """curl sends SIZE before RETR and gives up on a 550 (exit 78, "file does not exist"): the
    new user's first try of issue 32's review. The bytes are those an FTP client gets."""
    made = stored_job(run, 42)
    name = f"GEAR42_J{made['job_id']}.MPF"
    out = tmp_path / "curl.MPF"
    fetching = subprocess.run(["curl", "--silent", "--show-error", "--user", f"hobber-840d:{SECRETS['hobber-840d']}",
                               f"ftp://127.0.0.1:{serving}/{name}", "-o", str(out)],
                              capture_output=True, text=True, timeout=120, check=False)
    assert fetching.returncode == 0, fetching.stderr
    assert out.read_bytes() == fetched(serving, "hobber-840d", name)
    assert f"; PROGRAM {made['program_id']} TEMPLATE spur".encode() in out.read_bytes()


def test_the_bytes_sent_are_the_file_instantiate_job_writes(run, secrets, tmp_path):
    run.config.write_text(CONFIG + 'line_endings = "crlf"\n')   # the machine's files in CR LF
    job = stored_job(run, 43)["job_id"]
    out = tmp_path / "out"
    out.mkdir()
    written = run("instantiate", "--job", job, "--out", f"{out}/")
    assert written.exit_code == 0, written.output
    service = start_ftp_server(run.url, load_config(run.config, named=True))
    try:
        sent = fetched(service.port, "hobber-840d", f"GEAR43_J{job}.MPF")   # that program, proved again
        with psycopg.connect(run.url) as conn:   # the job edited since: its program is made again at RETR
            conn.execute("UPDATE job SET params = params || '{\"program_name\": \"WHEEL_43\"}' WHERE id = %s", (job,))
        remade = fetched(service.port, "hobber-840d", f"WHEEL_43_J{job}.MPF")
    finally:
        service.close()
    assert sent == (out / "GEAR43.MPF").read_bytes() and b"\r\n" in sent
    assert run("instantiate", "--job", job, "--out", f"{out}/").exit_code == 0
    again = (out / "WHEEL_43.MPF").read_bytes().decode()
    assert id_masked(remade.decode().split("\r\n")) == id_masked(again.split("\r\n"))   # but its own program id
    assert remade != sent and b"%_N_WHEEL_43_MPF" in remade


def test_a_draft_only_class_is_refused_with_its_reason_and_recorded(run, serving, tmp_path):
    job = draft_only_job(run, tmp_path)
    said = refusal_of(serving, "hobber-840d", f"RETR NC_PART_J{job}.MPF")
    assert said.startswith("550") and "class 'nc_part' has no released template version" in said
    [(machine, via, client, asked, job_id, program_id, refusal)] = requests(run.url)
    assert (machine, via, client, job_id, program_id) == ("hobber-840d", "ftp", "127.0.0.1", job, None)
    assert "no released template version" in refusal and said.endswith(refusal)


def test_a_job_whose_proof_fails_now_is_refused_and_recorded(run, serving):
    made = stored_job(run, 42)
    with psycopg.connect(run.url) as conn:   # the machine's record changed since: X now ends at 30 mm
        conn.execute("UPDATE machine SET x_max = 30 WHERE name = 'hobber-840d'")
    said = refusal_of(serving, "hobber-840d", f"RETR GEAR42_J{made['job_id']}.MPF")
    assert said.startswith("550") and "exceeds the travel of hobber-840d" in said and said.isascii()
    [row] = requests(run.url)
    assert row[4:6] == (made["job_id"], None) and "exceeds the travel" in row[6]
    with psycopg.connect(run.url) as conn:   # nothing stored: the job's one program is still the first
        assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == 1


def test_another_machines_job_is_not_sent(run, serving):
    fanuc = stored_job(run, 42, "hobber-fanuc")
    said = refusal_of(serving, "hobber-840d", f"RETR GEAR42_J{fanuc['job_id']}.MPF")
    assert said.startswith("550") and "job of machine hobber-fanuc, not of hobber-840d" in said
    assert requests(run.url)[0][4:6] == (None, None)   # the 840D's history names no Fanuc job


def test_a_fanuc_asks_by_its_o_number_as_m198_does(run, serving):
    job = stored_job(run, 42, "hobber-fanuc")["job_id"]   # O number: program_number_base 1000 + gear 42
    by_name = fetched(serving, "hobber-fanuc", f"GEAR42_J{job}.MPF")
    assert fetched(serving, "hobber-fanuc", "O1042") == by_name == fetched(serving, "hobber-fanuc", "o01042")
    assert "no stored job of O number 1043" in refusal_of(serving, "hobber-fanuc", "RETR O1043")
    assert "names no program" in refusal_of(serving, "hobber-fanuc", "RETR O0")


def test_two_machines_fetch_at_once(run, serving):
    jobs = {"hobber-840d": stored_job(run, 42)["job_id"], "hobber-fanuc": stored_job(run, 42, "hobber-fanuc")["job_id"]}
    start, got = threading.Barrier(2), {}

    def fetch(machine: str) -> None:
        client = login(serving, machine)
        start.wait(timeout=60)
        data = io.BytesIO()
        client.retrbinary(f"RETR GEAR42_J{jobs[machine]}.MPF", data.write)
        client.quit()
        got[machine] = data.getvalue()
    threads = [threading.Thread(target=fetch, args=(machine,)) for machine in jobs]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=120)
    assert b"; MACHINE hobber-840d" in got["hobber-840d"]
    assert got["hobber-fanuc"].startswith(b"%\nO1042")   # the Fanuc's program: O = 1000 + gear 42
    assert sorted((row[0], row[4]) for row in requests(run.url)) == sorted(jobs.items())
