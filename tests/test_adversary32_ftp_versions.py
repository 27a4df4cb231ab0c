"""Adversary of issue 32 (the engine held; guards not tested elsewhere): what RETR sends follows the
class's released version at the moment it is asked, never a draft and never a program forged in
SQL. Job of spur gear 42 on the 840D, fetched by FTP:
1. the class edited (a draft v2 writes "M9 ; COOLANT OFF" for row 2900's "M9"): the released v1
   program is sent, as it was;
2. v2 released (v1 retired): a new program of v2 is sent, with the new line;
3. a program forged into the job as its newest (the lines changed, the triggers bypassed): a new
   program is made and proved, the forged lines are never sent."""
import ftplib
import io
import json

import psycopg
from psycopg import sql

from engine.programs.config import load_config
from engine.service.ftp import start_ftp_server

EDIT = sql.SQL("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = 2900")
FORGE = """
INSERT INTO program (job_id, name, gear_class, template_version, template_hash, input_hash, lines, row_ids, trace,
                     unverified)
SELECT job_id, name, gear_class, template_version, template_hash, input_hash,
       array_replace(lines, 'M30', 'G0 X-999 M30'), row_ids, trace, unverified
FROM program WHERE job_id = %s ORDER BY id DESC LIMIT 1 RETURNING id, 'G0 X-999 M30' = ANY(lines)"""


def fetched(port: int, name: str) -> bytes:
    client = ftplib.FTP()
    client.connect("127.0.0.1", port, timeout=60)
    client.login("hobber-840d", "secret-840d")
    data = io.BytesIO()
    client.retrbinary(f"RETR {name}", data.write)
    client.quit()
    return data.getvalue()


def lineage(data: bytes) -> str:
    return next(line for line in data.decode().splitlines() if line.startswith("; PROGRAM "))


def test_retr_follows_the_release_never_a_draft_nor_a_forged_program(run, tmp_path, monkeypatch):
    made = json.loads(run("instantiate", "--gear", 42, "--machine", "hobber-840d", "--json").stdout)
    name = f"GEAR42_J{made['job_id']}.MPF"
    monkeypatch.setenv("ENGINE_FTP_SECRET_HOBBER_840D", "secret-840d")
    (tmp_path / "c.toml").write_text("")
    service = start_ftp_server(run.url, load_config(tmp_path / "c.toml", named=True))
    try:
        first = fetched(service.port, name)
        with psycopg.connect(run.url) as conn:
            conn.execute(EDIT, ('"M9 ; COOLANT OFF"',))   # a draft v2
        drafted = fetched(service.port, name)
        assert run("template", "release", "--class", "spur", "--yes").exit_code == 0
        released = fetched(service.port, name)
        with psycopg.connect(run.url) as conn:
            conn.execute("SET session_replication_role = replica")   # the forger bypasses the triggers
            forged, changed = conn.execute(FORGE, (made["job_id"],)).fetchone()
        assert changed   # the forged program does hold the line
        after_forgery = fetched(service.port, name)
    finally:
        service.close()
    assert drafted == first and f"; PROGRAM {made['program_id']} TEMPLATE spur v1 " in lineage(first)
    assert b"M9 ; COOLANT OFF" not in first
    assert " TEMPLATE spur v2 " in lineage(released) and b"M9 ; COOLANT OFF" in released
    assert b"X-999" not in after_forgery and f"; PROGRAM {forged} " not in lineage(after_forgery)
    assert " TEMPLATE spur v2 " in lineage(after_forgery)
