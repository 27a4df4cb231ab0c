"""Adversary of issue 32 (the engine held; a guard): what a share may hold besides a request is
never read as one, and a request of garbage is refused in one line and recorded. A FIFO named like
a request (opening it would block the service for every machine), a folder named like one, and a
1 MiB binary request with NULs and no new line in its first KiB."""
import os

import psycopg

from engine.programs.config import Config
from engine.service.request_folder import RequestFolder


def test_a_fifo_a_folder_and_a_binary_request(run, tmp_path):
    root = tmp_path / "share"
    root.mkdir()
    folder = RequestFolder(root, ["hobber-840d"], run.url, Config())
    share = root / "hobber-840d"
    os.mkfifo(share / "PIPE.REQ")
    (share / "DIR.REQ").mkdir()
    (share / "BIN.REQ").write_bytes(bytes(range(256)) * 4096)
    try:
        answers = folder.poll_once() + folder.poll_once()
    finally:
        folder.close()
    assert [answer.request for answer in answers] == ["BIN.REQ"] and answers[0].program_file is None
    reason, request_words = (share / "BIN.ERR").read_text().split("\n", 1)
    assert request_words.count("\n") == 1 and (reason + request_words).isascii()   # two lines: reason, request
    assert "a request is one line" in reason   # it has line breaks
    assert (share / "PIPE.REQ").exists() and (share / "DIR.REQ").is_dir()   # left alone
    with psycopg.connect(run.url) as conn:
        [(asked, refusal)] = conn.execute("SELECT asked_for, refusal FROM program_request").fetchall()
    assert "\x00" not in asked and len(asked) <= 200 and refusal == reason.strip()
