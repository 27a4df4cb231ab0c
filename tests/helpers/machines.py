"""A machine record made in a test from a seeded one with some fields changed (rolled back with the
test's transaction)."""
from __future__ import annotations

from psycopg import sql


def add_machine_like(conn, like: str, name: str, **changes) -> str:
    """Insert a copy of machine `like` named `name` with `changes` (column -> value); a reversed Z
    (z_direction -1) mirrors the Z travel and load Z too (Z_prog = −Z_DIN). Returns the name."""
    conn.execute("CREATE TEMP TABLE machine_copy ON COMMIT DROP AS SELECT * FROM machine WHERE name = %s", (like,))
    conn.execute("UPDATE machine_copy SET name = %s", (name,))
    for column, value in changes.items():
        conn.execute(sql.SQL("UPDATE machine_copy SET {} = %s").format(sql.Identifier(column)), (value,))
    if changes.get("z_direction") == -1:
        conn.execute("UPDATE machine_copy SET z_min = -z_max, z_max = -z_min, load_z = -load_z")
    conn.execute("INSERT INTO machine SELECT * FROM machine_copy")
    conn.execute("DROP TABLE machine_copy")
    return name
