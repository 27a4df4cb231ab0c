"""The floor-to-floor time on a hobbing program's header (issue 29, reference §B16): the cycle time
plus what the program does besides moving, at the times the machine record states. The expected
time is computed here from the program text and the seeded hobber-840d's sample times (swivel
10 °/s, spindle run-up 3 s, synchronisation 2 s, tailstock 2 s each way, door 3 s each way, tool
call 0 s, loading and unloading 30 s), its cycle time by tests/helpers/simulation_programs'
own reading of the blocks; the simulation refuses a header that says otherwise."""
from __future__ import annotations

import re

import pytest
from helpers.simulation_programs import LOAD, RAPID_RATE, program_minutes

from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program

SAMPLE = {"swivel": 10.0, "runup": 3.0, "sync": 2.0, "tailstock": 2.0, "door": 3.0, "tool": 0.0, "load": 30.0}
FLOOR = re.compile(r"; FLOOR TO FLOOR ([0-9.]+) MIN")


def expected_minutes(lines: list[str]) -> float:
    """Cycle time plus handling_minutes."""
    return program_minutes(lines, RAPID_RATE, LOAD) + handling_minutes(lines)


def handling_minutes(lines: list[str]) -> float:
    """|A| from 0° at 10 °/s, 3 s per M3, 2 s per EGON, 2 s per M20 and per M21, no door blocks
    on this machine, 30 s loading and unloading."""
    code = [line.partition(";")[0] for line in lines]
    swivel = sum(abs(float(match.group(1))) for line in code for match in re.finditer(r"\bA=(-?[0-9.]+)", line))
    seconds = (swivel / SAMPLE["swivel"] + SAMPLE["runup"] * sum(bool(re.search(r"\bM3\b", c)) for c in code)
               + SAMPLE["sync"] * sum(c.strip().startswith("EGON(") for c in code)
               + SAMPLE["tailstock"] * sum(bool(re.search(r"\bM2[01]\b", c)) for c in code)
               + SAMPLE["tool"] * sum(bool(re.search(r"\bT[0-9]", c)) for c in code) + SAMPLE["load"])
    return seconds / 60


def stated(lines: list[str]) -> float:
    return float(next(FLOOR.fullmatch(line).group(1) for line in lines if FLOOR.fullmatch(line)))


@pytest.mark.parametrize("gear_id, choices", [(42, {}), (42, {"tailstock": False}), (43, {"cuts": 2}),
                                              (53, {"worm_feed": "tangential"}), (54, {})])
def test_the_header_states_the_programs_floor_to_floor_time(conn, gear_id, choices):
    program = instantiate_gear(conn, gear_id, choices=Choices(**choices))
    assert stated(program.lines) == pytest.approx(expected_minutes(program.lines), abs=0.051)
    cycle, floor = conn.execute("SELECT (params->>'cycle_time')::float, (params->>'floor_to_floor')::float "
                                "FROM job WHERE id = %s", (program.job_id,)).fetchone()
    assert floor - cycle == pytest.approx(handling_minutes(program.lines), abs=1e-4)   # the job's, unrounded
    assert stated(program.lines) > float(next(line.split()[3] for line in program.lines
                                             if line.startswith("; CYCLE TIME ")))


def test_a_duplex_gear_synchronises_once_per_unit(conn):
    lines = instantiate_gear(conn, 54).lines
    assert sum(line.startswith("EGON(") for line in lines) == 2


def simulated(conn, lines: list[str], made: list[str]):
    """The simulation's report of `lines` for gear 42 with the hob the engine's program `made` names."""
    hob_id = next(line.split()[2] for line in made if line.startswith("; HOB "))
    hob = next(hob for hob in load_hobs(conn) if hob.id == hob_id)
    return simulate_program(lines, load_gear(conn, 42), hob, load_machine(conn, "hobber-840d"))


def refusals(report) -> list[str]:
    return [finding.message for finding in report.findings if finding.refuses]


def test_a_header_that_says_another_time_is_refused(conn):
    program = instantiate_gear(conn, 42)
    assert not refusals(simulated(conn, program.lines, program.lines))
    minutes = stated(program.lines)
    edited = [f"; FLOOR TO FLOOR {minutes + 0.6:.1f} MIN" if FLOOR.fullmatch(line) else line for line in program.lines]
    assert any("floor-to-floor time of" in message for message in refusals(simulated(conn, edited, program.lines)))
    loose = [line.replace("; FLOOR TO FLOOR", "; floor to floor") for line in program.lines]
    assert any("canonical whole-line form" in message for message in refusals(simulated(conn, loose, program.lines)))


def test_a_machine_that_does_not_state_its_times_gets_no_line_and_refuses_one(conn):
    conn.execute("UPDATE machine SET load_unload_time = NULL WHERE name = 'hobber-840d'")
    program = instantiate_gear(conn, 42)
    assert not any(FLOOR.fullmatch(line) for line in program.lines)
    claimed = program.lines[:2] + ["; FLOOR TO FLOOR 3.0 MIN"] + program.lines[2:]
    assert any("does not state load_unload_time" in message
               for message in refusals(simulated(conn, claimed, program.lines)))


def test_a_machine_that_states_some_of_its_times_is_told_which_are_missing(conn):
    """New-user review 29: a machine stating some times and not others got no line and no word."""
    conn.execute("UPDATE machine SET door_time = NULL, load_unload_time = NULL WHERE name = 'hobber-840d'")
    program = instantiate_gear(conn, 42)
    assert not any(FLOOR.fullmatch(line) for line in program.lines)
    assert any("no floor-to-floor time: machine hobber-840d does not state door_time, load_unload_time" in note
               for note in program.notes), program.notes
