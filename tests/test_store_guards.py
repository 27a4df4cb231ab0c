"""Two layers of the store that the layers around them hide from every other test (issue 28: a
fault planted in each failed no test of the whole suite): a dry run's transaction, which the
database itself holds to reading (the dry-run code writes nothing today; the guard keeps a
future write from being stored by a command that promised to store nothing), and the store's
own check of a program's name and lines (the verifier refuses such a line before it, the
database's check_program after it; this one names the line and the fix in the engine's words)."""
from __future__ import annotations

import psycopg
import pytest

from engine.errors import EngineError
from engine.programs.batches import read_only
from engine.programs.storage import refuse_unsafe


def test_a_dry_runs_transaction_refuses_every_write_nextval_too(conn):
    with pytest.raises(psycopg.errors.ReadOnlySqlTransaction):
        with read_only(conn):
            conn.execute("SELECT nextval('job_id_seq')")   # a sequence moves even when its transaction rolls back
    assert conn.execute("SELECT 1").fetchone() == (1,)    # the caller's own transaction goes on


def test_a_dry_runs_transaction_is_rolled_back_not_released(conn):
    """Inside a caller's transaction the dry run is a savepoint: rolled back, a SET LOCAL made in
    it is undone at its end (released, the setting would last to the caller's COMMIT)."""
    before = conn.execute("SHOW application_name").fetchone()[0]
    with read_only(conn):
        conn.execute("SET LOCAL application_name = 'dry run'")
    assert conn.execute("SHOW application_name").fetchone()[0] == before


@pytest.mark.parametrize("breaking, shown", [("\n", r"'\n'"), ("\r", r"'\r'"), ("\u2028", r"'\u2028'")])
def test_the_store_refuses_a_line_that_would_start_another_block(breaking, shown):
    lines = ["%_N_GEAR42_MPF", f"; GEAR{breaking}G0 X9999 Z-9999", "M30"]
    with pytest.raises(EngineError) as refused:
        refuse_unsafe("GEAR42", lines)
    said = str(refused.value)
    assert "line 2" in said and shown in said and "another NC block" in said and "nothing stored" in said


def test_the_store_refuses_a_control_character_and_an_unsafe_name():
    with pytest.raises(EngineError, match=r"line 1 'G1\\tX10' holds '\\t': a stored NC line holds no control"):
        refuse_unsafe("GEAR42", ["G1\tX10"])
    with pytest.raises(EngineError, match="not a safe program name"):
        refuse_unsafe("../x", ["M30"])
    refuse_unsafe("GEAR42", ["%_N_GEAR42_MPF", "G1 X10 F100", "M30"])   # a clean program passes
