"""`engine serve` with the delivery to the controls (issue 32): one service runs the web view, the
FTP server (--ftp-port) and the request folders (--requests), started as a shop starts it and
stopped with `engine serve stop`; what cannot start stops the service in one line, exit 1."""
from __future__ import annotations

import ftplib
import io
import time

import psycopg
import pytest
from helpers.serve_process import engine, free_port

MACHINE = "hobber-840d"
SECRET = "a machine's own secret"
WAIT = 30   # seconds: no answer of this file takes longer, so a bug fails instead of hanging


def first_job(url: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT max(id) FROM job").fetchone()[0]


def stored_text(url: str, program_id: int) -> bytes:
    with psycopg.connect(url) as conn:
        lines = conn.execute("SELECT lines FROM program WHERE id = %s", (program_id,)).fetchone()[0]
    return ("\n".join(lines) + "\n").encode()


def answered(path, deadline: float) -> bool:
    while time.monotonic() < deadline and not path.exists():
        time.sleep(0.1)
    return path.exists()


@pytest.mark.slow   # the whole service as a process: seconds; every full run runs it (issue 28: test-fast)
def test_one_service_serves_the_web_view_ftp_and_request_folders_until_stopped(run, tmp_path):
    assert run("instantiate", "--gear", "42").exit_code == 0
    job = first_job(run.url)
    root = tmp_path / "requests"
    root.mkdir()
    ftp_port = free_port()
    service = engine("--database-url", run.url, "serve", "--port", str(free_port()), "--ftp-port", str(ftp_port),
                     "--requests", str(root), "--request-machine", MACHINE, runtime=tmp_path,
                     env_extra={"ENGINE_FTP_SECRET_HOBBER_840D": SECRET})
    try:
        said = [service.stdout.readline() for _ in range(3)]
        assert f"127.0.0.1:{ftp_port}" in said[0] and SECRET not in "".join(said)
        assert f"request folders under {root} for {MACHINE}" in said[1] and "serving the web view" in said[2]
        with ftplib.FTP() as ftp:
            ftp.connect("127.0.0.1", ftp_port, timeout=WAIT)
            ftp.login(MACHINE, SECRET)
            [name] = ftp.nlst()
            fetched = io.BytesIO()
            ftp.retrbinary(f"RETR {name}", fetched.write)
        (root / MACHINE / "ASK.REQ").write_text(f"JOB {job}\n")
        assert answered(root / MACHINE / "ASK.RDY", time.monotonic() + WAIT)
        program_file, answered_request = (root / MACHINE / "ASK.RDY").read_text().splitlines()
        assert answered_request == f"JOB {job}"
        written = (root / MACHINE / program_file).read_bytes()
        with psycopg.connect(run.url) as conn:
            requests = conn.execute("SELECT via, program_id FROM program_request ORDER BY id").fetchall()
        assert [via for via, _ in requests] == ["ftp", "folder"]
        assert fetched.getvalue() == stored_text(run.url, requests[0][1])
        assert written == stored_text(run.url, requests[1][1])
        stop = engine("serve", "stop", runtime=tmp_path)
        assert stop.wait(WAIT) == 0
        assert service.wait(WAIT) == 0
    finally:
        if service.poll() is None:
            service.kill()


def test_a_request_root_that_does_not_exist_stops_the_service_in_one_line(read_only_database_url, tmp_path):
    service = engine("--database-url", read_only_database_url, "serve", "--port", str(free_port()),
                     "--requests", str(tmp_path / "no such share"), runtime=tmp_path)
    out, err = service.communicate(timeout=WAIT)
    assert service.returncode == 1 and len(err.splitlines()) == 1 and "does not exist" in err
    assert "serving" not in out


def test_delivery_options_without_their_part_are_refused(read_only_run, tmp_path):
    machine_alone = read_only_run("serve", "--request-machine", MACHINE, env={"ENGINE_RUNTIME_DIR": str(tmp_path)})
    host_alone = read_only_run("serve", "--ftp-host", "127.0.0.1", env={"ENGINE_RUNTIME_DIR": str(tmp_path)})
    assert machine_alone.exit_code == host_alone.exit_code == 1
    assert "give --requests ROOT too" in machine_alone.stderr and "give --ftp-port too" in host_alone.stderr
