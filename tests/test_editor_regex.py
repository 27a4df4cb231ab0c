"""Golden-test patterns run in linear time (issue 26): RE2 runs them, so `match: ^(.+)+!$`, which
Python's backtracking `re` took minutes over on a line of gear 42's program, ends at once; a
pattern RE2 cannot run (a backreference, lookaround) is refused in one line naming the test,
when the test is seeded and when it runs (a DBA writes tests in SQL). docs/guide/release-and-golden-tests.md."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest

from engine.errors import EngineError
from engine.library.seed import seed
from engine.paths import SEED_DIR

ROOT = Path(__file__).resolve().parents[1]
HANG_GUARD = 20   # seconds: far more than a linear match takes; on the backtracking engine it hung
CATASTROPHIC = "match: ^(.+)+!$"          # 2^n ways to split a line of n characters before failing
BACKREFERENCE = r"match: ^(G\d+) .* \1"    # a block repeating its first G word: RE2 has no \1


def engine_test(url: str) -> subprocess.CompletedProcess:
    """`engine test --class spur` in its own process, ended if it hangs."""
    return subprocess.run([sys.executable, "-m", "engine", "--database-url", url, "test", "--class", "spur"],
                          capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)},
                          timeout=HANG_GUARD)


def add_test(url: str, name: str, expectation: str) -> None:
    with psycopg.connect(url) as conn:   # as a DBA would, in SQL
        conn.execute("INSERT INTO template_test (gear_class, name, gear_id, expect) VALUES ('spur', %s, 42, %s)",
                     (name, [expectation]))


def failure_of(done: subprocess.CompletedProcess, name: str) -> str:
    failing = [line for line in done.stdout.splitlines() if f"spur/{name}" in line]
    assert len(failing) == 1 and failing[0].startswith("FAIL"), done.stdout
    return failing[0]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_catastrophic_pattern_is_matched_in_linear_time(fresh_database_url):
    add_test(fresh_database_url, "catastrophic", CATASTROPHIC)
    done = engine_test(fresh_database_url)   # on main: TimeoutExpired (re backtracks 2^n)
    assert done.returncode == 1
    assert "no line matches" in failure_of(done, "catastrophic")


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_backreference_fails_its_test_in_one_line_naming_it(fresh_database_url):
    add_test(fresh_database_url, "backreference", BACKREFERENCE)
    done = engine_test(fresh_database_url)
    assert done.returncode == 1 and done.stderr == "", done.stderr
    failure = failure_of(done, "backreference")
    assert "RE2" in failure and "backreferences" in failure, failure


def test_a_seeded_test_with_a_backreference_is_refused_and_nothing_is_seeded(fresh_database_url, tmp_path):
    directory = tmp_path / "seed"
    shutil.copytree(SEED_DIR, directory)
    tests_file = directory / "template_tests.json"
    tests = json.loads(tests_file.read_text(encoding="utf-8"))
    tests.append({"class": "spur", "name": "added-later", "params": None, "gear_id": 42, "expect": ["line: M30"]})
    tests.append({"class": "spur", "name": "backreference", "gear_id": 42, "expect": ["line: M30", BACKREFERENCE]})
    tests_file.write_text(json.dumps(tests), encoding="utf-8")
    with psycopg.connect(fresh_database_url) as conn:
        before = conn.execute("SELECT count(*) FROM template_test").fetchone()
        with pytest.raises(EngineError) as refused:
            seed(conn, directory, samples=True)
        conn.rollback()
        assert conn.execute("SELECT count(*) FROM template_test").fetchone() == before
    message = str(refused.value)
    assert "\n" not in message and "spur/backreference" in message and "RE2" in message, message
