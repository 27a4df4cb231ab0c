"""Releasing a class's draft inside a test, as the gate (`engine template release`) finally does:
through the database's release_template (as the superuser the tests run as, or as
engine_releaser), with the version the draft has now and the hash of its rows."""
from __future__ import annotations

# The hash of the class's current assembled rows: what release_template compares with the stored
# version's (it stores a version made in this transaction first).
RELEASE_DRAFT = """
SELECT release_template(g.name, g.template_version, template_rows_hash(r.rows))
FROM gear_class g CROSS JOIN assembled_rows_of(ARRAY[g.name]) r
WHERE g.name = %s"""


def release_draft(conn, gear_class: str) -> int:
    """Release the class's current version (its draft); → the release's id."""
    return conn.execute(RELEASE_DRAFT, (gear_class,)).fetchone()[0]
