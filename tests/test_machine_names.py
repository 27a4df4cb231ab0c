"""`--machine` finds a record by its name written in any case, as `engine machines import` holds
names that differ only in case to be one machine (a new user's `--machine Shop-Fanuc` was "does
not exist" for the record shop-fanuc); two records that differ only in case (made in SQL) are
named exactly or not at all."""
from __future__ import annotations

import pytest

from engine.errors import EngineError
from engine.machines.records import load_machine

TWIN = ["CREATE TEMP TABLE twin AS SELECT * FROM machine WHERE name = 'hobber-fanuc'",
        "UPDATE twin SET name = 'Hobber-Fanuc'", "INSERT INTO machine SELECT * FROM twin"]


def test_a_machine_is_found_by_its_name_in_another_case(conn):
    assert load_machine(conn, "HOBBER-FANUC").name == "hobber-fanuc"


def test_two_records_differing_only_in_case_are_found_only_by_the_exact_name(conn):
    for statement in TWIN:
        conn.execute(statement)
    assert load_machine(conn, "Hobber-Fanuc").name == "Hobber-Fanuc"
    assert load_machine(conn, "hobber-fanuc").name == "hobber-fanuc"
    with pytest.raises(EngineError, match="machine 'HOBBER-FANUC' does not exist; known machines: "):
        load_machine(conn, "HOBBER-FANUC")
