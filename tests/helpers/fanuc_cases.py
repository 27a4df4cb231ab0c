"""A seeded gear's 840D hobbing program, made by the seeded templates without the simulation's
proof (tests/helpers/unproved_programs.py), with the records it is proved against: the test
rewrites it in the Fanuc form (tests/helpers/fanuc_programs.py) and proves both."""
from __future__ import annotations

from msgspec.structs import replace

from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from helpers.unproved_programs import unproved

MACHINE = "hobber-840d"
CLAMPED = Choices()             # the templates' default: the tailstock clamped (M20 … M21)


def twin(conn, monkeypatch, gear_id: int, choices: Choices = CLAMPED, **senses):
    """(840D lines, gear, hob, the 840D record with `senses`, the same record in dialect fanuc)."""
    program = unproved(conn, monkeypatch, gear_id, choices)
    hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    hob = next(h for h in load_hobs(conn) if h.id == hob_id)
    machine = replace(load_machine(conn, MACHINE), **senses)
    return program.lines, load_gear(conn, gear_id), hob, machine, replace(machine, dialect="fanuc")
