"""The machine table and its CSV files as the machines import/export tests read and write them."""
from __future__ import annotations

import csv
import io

import psycopg

from helpers.class_jobs import ok


def machines(url) -> list[dict]:
    """Every stored machine record, every column, by name."""
    with psycopg.connect(url) as conn:
        cursor = conn.execute("SELECT * FROM machine ORDER BY name")
        names = [column.name for column in cursor.description]
        return [dict(zip(names, row)) for row in cursor]


def exported(run) -> list[dict]:
    """The rows `engine machines list --csv` writes."""
    return list(csv.DictReader(io.StringIO(ok(run("machines", "list", "--csv")).stdout)))


def written(tmp_path, rows: list[dict]) -> str:
    """machines.csv of the rows (the columns of all of them; a row without one leaves it empty)."""
    path = tmp_path / "machines.csv"
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(dict.fromkeys(key for row in rows for key in row)), restval="")
        writer.writeheader()
        writer.writerows(rows)
    return str(path)
