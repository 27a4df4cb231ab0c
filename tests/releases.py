"""Releasing a class's draft inside a test, as the gate (`engine template release`) finally does:
through the database's release_template (the test user is a superuser, so it may), with the
version and hash the draft has now."""
from __future__ import annotations

RELEASE_DRAFT = """
SELECT release_template(g.name, g.template_version, v.hash)
FROM gear_class g JOIN template_version_rows v ON v.gear_class = g.name AND v.version = g.template_version
WHERE g.name = %s"""
# A version is stored when it is committed, or when a program is made from it; the draft of an
# edit made in this transaction is stored here first.
STORE_DRAFT = "SELECT store_current_version(%s)"
CURRENT_VERSION_STORED = """
SELECT 1 FROM template_version_rows v JOIN gear_class g ON g.name = v.gear_class AND g.template_version = v.version
WHERE g.name = %s"""


def release_draft(conn, gear_class: str) -> int:
    """Release the class's current version (its draft); → the release's id."""
    if conn.execute(CURRENT_VERSION_STORED, (gear_class,)).fetchone() is None:
        conn.execute(STORE_DRAFT, (gear_class,))
    return conn.execute(RELEASE_DRAFT, (gear_class,)).fetchone()[0]
