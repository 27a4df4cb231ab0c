"""Adversary of issue 32: a refusal sent to a control names the thing and what to do, never the
service's private folder. A lathe class job on a blank the engine assumed is refused as a file by
`instantiate --job --out`; the delivery makes it in a temporary folder, and the refusal read "it is
never written to a file (/tmp/engine-delivery-x8k2/SHAFT.MPF)": a path that is gone, on another
computer, shown on the control and recorded."""
import ftplib

import psycopg
from helpers.class_jobs import SHAFT_PROGRAM as SHAFT

from engine.programs.config import load_config
from engine.service.ftp import start_ftp_server


def test_an_assumed_blank_is_refused_without_the_services_folder(run, tmp_path, monkeypatch):
    (tmp_path / "shaft.nc").write_text(SHAFT)
    assert run("import-nc", tmp_path / "shaft.nc", "--class", "shaft").exit_code == 0
    assert run("template", "release", "--class", "shaft", "--yes", "--without-golden-tests").exit_code == 0
    assert run("instantiate", "--class", "shaft", "--machine", "lathe-iso").exit_code == 0   # stored, no file
    with psycopg.connect(run.url) as conn:
        job = conn.execute("SELECT max(id) FROM job").fetchone()[0]
    monkeypatch.setenv("ENGINE_FTP_SECRET_LATHE_ISO", "lathe-secret")
    (tmp_path / "c.toml").write_text("")
    service = start_ftp_server(run.url, load_config(tmp_path / "c.toml", named=True))
    client = ftplib.FTP()
    try:
        client.connect("127.0.0.1", service.port, timeout=60)
        client.login("lathe-iso", "lathe-secret")
        try:
            client.retrbinary(f"RETR SHAFT_J{job}.MPF", lambda _: None)
            said = ""
        except ftplib.error_perm as refused:
            said = str(refused)
        client.close()
    finally:
        service.close()
    assert said.startswith("550") and "blank assumed" in said and "stock_diameter" in said
    assert "engine-delivery-" not in said and "/tmp" not in said and "SHAFT.MPF" in said
    with psycopg.connect(run.url) as conn:
        [recorded] = conn.execute("SELECT refusal FROM program_request").fetchone()
    assert said.endswith(recorded)
