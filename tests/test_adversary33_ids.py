"""Issue 33's adversary: a sequence moved by hand out of this database's id range (setval to another
plant's ids). The trigger a_plant_id refuses the row; the refusal must be one line, exit 1 (not an
unexpected error), and `engine plant status`, which that refusal names, must say which sequence."""
from __future__ import annotations

import json

import psycopg

PLANT_3_IDS = 3 * 10**10   # docs/design.md §12: plant 3 makes ids from 3·10^10


def test_a_sequence_moved_into_another_plants_range_is_refused_and_named_by_status(run):
    with psycopg.connect(run.url, autocommit=True) as conn:
        conn.execute("SELECT setval('job_id_seq', %s)", (PLANT_3_IDS,))
    refused = run("instantiate", "--gear", 42)
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert "plant 0 makes ids 1 to 9999999999" in refused.stderr and "nothing stored" in refused.stderr
    status = json.loads(run("plant", "status", "--json").stdout)
    assert [w for w in status["warnings"] if "job_id_seq" in w and "setval" in w]
