"""Adversary of issue 32 (the engine held; guards not tested elsewhere), with ftplib and a raw socket
against a real server: the data connection never goes to a third host (PORT/EPRT bounce, FXP), a
path out of the machine's folder or into another's is refused, and bytes that are no UTF-8 in a
name are refused in one line and recorded."""
import ftplib
import json
import socket

import psycopg
import pytest

from engine.programs.config import load_config
from engine.service.ftp import start_ftp_server


@pytest.fixture
def served(run, tmp_path, monkeypatch):
    jobs = {machine: json.loads(run("instantiate", "--gear", 42, "--machine", machine, "--json").stdout)["job_id"]
            for machine in ("hobber-840d", "hobber-fanuc")}
    monkeypatch.setenv("ENGINE_FTP_SECRET_HOBBER_840D", "secret-840d")
    (tmp_path / "c.toml").write_text("")
    service = start_ftp_server(run.url, load_config(tmp_path / "c.toml", named=True))
    client = ftplib.FTP()
    client.connect("127.0.0.1", service.port, timeout=60)
    client.login("hobber-840d", "secret-840d")
    yield service.port, client, jobs
    client.close()
    service.close()


def refused(client: ftplib.FTP, command: str) -> str:
    with pytest.raises(ftplib.error_perm) as answer:
        client.sendcmd(command)
    return str(answer.value)


def test_no_data_connection_to_a_third_host(served):
    _, client, _ = served
    assert refused(client, "PORT 10,0,0,1,4,1").startswith("501 Rejected data connection to foreign address")
    assert refused(client, "EPRT |1|10.0.0.1|1025|").startswith("501 Rejected data connection to foreign address")


def test_no_path_leaves_the_machines_folder(run, served):
    _, client, jobs = served
    fanuc = jobs["hobber-fanuc"]
    for name in (f"../hobber-fanuc/GEAR42_J{fanuc}.MPF", "/etc/passwd", "../../etc/passwd"):
        assert refused(client, f"MDTM {name}").startswith("550"), name
    with pytest.raises(ftplib.error_perm, match="^550"):
        client.retrbinary(f"RETR ../hobber-fanuc/GEAR42_J{fanuc}.MPF", lambda _: None)
    with psycopg.connect(run.url) as conn:   # nothing of the Fanuc's was sent to the 840D
        assert conn.execute("SELECT count(*) FROM program_request WHERE program_id IS NOT NULL").fetchone()[0] == 0


def test_a_name_of_bytes_that_are_no_utf8_is_refused_and_recorded(run, served):
    port, _, jobs = served
    raw = socket.create_connection(("127.0.0.1", port), timeout=60)
    answers = raw.makefile("rb")
    answers.readline()
    for line in (b"USER hobber-840d", b"PASS secret-840d", b"RETR GEAR42_J%d\xff.MPF" % jobs["hobber-840d"]):
        raw.sendall(line + b"\r\n")
        said = answers.readline()
    raw.close()
    assert said.startswith(b"550 ") and b"names no program" in said and said.isascii()
    with psycopg.connect(run.url) as conn:
        [(asked, program)] = conn.execute("SELECT asked_for, program_id FROM program_request").fetchall()
    assert program is None and asked.startswith("GEAR42_J")
