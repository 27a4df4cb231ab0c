"""Ctrl-C during a batch planned by workers (issue 31): the terminal sends SIGINT to the whole
process group, parent and workers; the workers end with the parent without a word (before: each
printed `Process ForkPoolWorker-N:` and, once, a traceback), the parent says so in one line and
exits 130 (128 + SIGINT, as a shell reports it), and nothing of the batch is stored. Before,
a Ctrl-C as the workers started could also leave the parent waiting forever for a dead worker."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest

ROOT = Path(__file__).resolve().parent.parent
BATCH_GEARS = 300
INTERRUPTED = 128 + signal.SIGINT


def counts(url) -> tuple[int, int]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM program), (SELECT count(*) FROM job)").fetchone()


def children(pid: int) -> list[int]:
    """The processes `pid` forked that are still its children (Linux /proc)."""
    try:
        return [int(child) for child in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


@pytest.mark.slow   # seconds: out of the fast subset, in every full run
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="reads the workers from Linux's /proc")
def test_ctrl_c_ends_the_workers_quietly_with_the_parent_and_stores_nothing(fresh_database_url):
    with psycopg.connect(fresh_database_url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, material, hardness, quality_grade) "
                     "SELECT 100000 + g, 'spur', 2, 19 + g %% 40, 20, '40Cr', 170 + g %% 100, 7 "
                     "FROM generate_series(1, %s) g", (BATCH_GEARS,))
    before = counts(fresh_database_url)
    batch = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", fresh_database_url, "instantiate",
                              "--gears", f"100001-{100000 + BATCH_GEARS}", "--workers", "2"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    workers: list[int] = []
    while len(workers) < 2 and batch.poll() is None:   # the pool is forked once the batch's classes are read
        workers = children(batch.pid)
    os.killpg(batch.pid, signal.SIGINT)                # what Ctrl-C on the terminal does
    try:
        stderr = batch.communicate(timeout=300)[1]
    except subprocess.TimeoutExpired:   # before issue 31 the parent could wait forever for a worker Ctrl-C ended
        os.killpg(batch.pid, signal.SIGKILL)
        pytest.fail(f"the batch did not end after Ctrl-C: {batch.communicate()[1]}")
    assert len(workers) == 2, f"the batch ended before its workers started: {stderr}"
    assert batch.returncode == INTERRUPTED, stderr
    assert "Traceback" not in stderr and "ForkPoolWorker" not in stderr, stderr
    assert stderr == "error: interrupted (Ctrl-C); what was not yet committed was rolled back\n"
    assert counts(fresh_database_url) == before
    assert not [pid for pid in workers if Path(f"/proc/{pid}").exists()]   # the workers ended with it
