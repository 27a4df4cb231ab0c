"""Adversary of issue 32: each machine logs in to FTP with its own secret. The default variable is
ENGINE_FTP_SECRET_<NAME> with every character but a letter or digit an underscore, so machines
`hobber-fanuc` and `hobber_fanuc` (both legal names) read the same variable: the one secret set for
one of them logged in as the other too, and fetched its programs. A variable two machines would
read is nobody's: both are refused until each has its own (ftp_secret_env)."""
import ftplib

import psycopg
import pytest

from engine.programs.config import load_config
from engine.service.ftp import start_ftp_server

TWIN = ("INSERT INTO machine SELECT (jsonb_populate_record(m, jsonb_build_object('name', 'hobber_fanuc'))).* "
        "FROM machine m WHERE name = 'hobber-fanuc'")


def logs_in(port: int, machine: str, secret: str) -> bool:
    client = ftplib.FTP()
    client.connect("127.0.0.1", port, timeout=60)
    try:
        client.login(machine, secret)
    except ftplib.error_perm:
        return False
    finally:
        client.close()
    return True


@pytest.mark.parametrize("own_variable", [False, True])
def test_two_machines_reading_one_secret_variable_cannot_log_in(run, tmp_path, monkeypatch, own_variable):
    with psycopg.connect(run.url) as conn:
        conn.execute(TWIN)
    monkeypatch.setenv("ENGINE_FTP_SECRET_HOBBER_FANUC", "shared-secret")
    monkeypatch.setenv("FANUC_OWN", "own-secret")
    (tmp_path / "c.toml").write_text('[machines.hobber-fanuc]\nftp_secret_env = "FANUC_OWN"\n' if own_variable else "")
    service = start_ftp_server(run.url, load_config(tmp_path / "c.toml", named=True), failed_login_delay=0.01)
    try:
        if own_variable:   # each reads its own variable: each logs in with its own secret only
            assert logs_in(service.port, "hobber-fanuc", "own-secret")
            assert logs_in(service.port, "hobber_fanuc", "shared-secret")
            assert not logs_in(service.port, "hobber-fanuc", "shared-secret")
        else:
            assert not logs_in(service.port, "hobber-fanuc", "shared-secret")
            assert not logs_in(service.port, "hobber_fanuc", "shared-secret")
    finally:
        service.close()
