"""The simulation on the programs the seeded templates make for the seeded gears, per class and
job choice, exactly as the templates write them; `instantiate` stores only what the
simulation proves, and `engine simulate --program ID` says what the library says."""
from __future__ import annotations

import json

import pytest
from helpers.unproved_programs import unproved

from engine.errors import EngineError
from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs import verified_run
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program, simulate_stored_program

MACHINE = "hobber-840d"
CASES = [   # gear, class, job choices
    (42, "spur", Choices()), (42, "spur conventional", Choices(feed_mode="conventional")),
    (42, "spur shift per part", Choices(shift_per_part=2.0)), (42, "spur no tailstock", Choices(tailstock=False)),
    (45, "spur rough + finish", Choices()), (46, "spur m1.5 2-start hob", Choices()),
    (43, "helical right hand", Choices()), (44, "helical left hand", Choices()),
    (47, "helical β20 conventional-climb", Choices(feed_mode="conventional-climb", cuts=2)),
    (51, "crowned", Choices()), (53, "worm wheel radial", Choices()),
    (53, "worm wheel tangential", Choices(worm_feed="tangential")), (54, "duplex", Choices()),
]


def simulated(conn, monkeypatch, gear_id: int, choices: Choices):
    program = unproved(conn, monkeypatch, gear_id, choices)
    hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    gear, machine = load_gear(conn, gear_id), load_machine(conn, MACHINE)
    hob = next(h for h in load_hobs(conn) if h.id == hob_id)
    return simulate_program(program.lines, gear, hob, machine, program.name)


@pytest.mark.parametrize("gear_id, what, choices", CASES, ids=[case[1] for case in CASES])
def test_seeded_gear_programs_set_to_the_reference_simulate_clean(conn, monkeypatch, gear_id, what, choices):
    report = simulated(conn, monkeypatch, gear_id, choices)
    assert not report.refusals, "\n".join(report.lines())
    gear = load_gear(conn, gear_id)
    assert report.teeth == [str(t) for t in [gear.teeth, *(u.teeth for u in gear.units)]]
    assert all(abs(cut.stock_left) <= 0.01 for cut in report.cuts[-1 - len(gear.units):])


def test_the_seeded_taper_gear_50_is_cut_to_the_cone_root_and_no_deeper(conn, monkeypatch):
    """The tip circle's envelope along a slanted path lies r0/cos δ from the path, not r0
    (reference §B12): a centre distance of (d_f2 + d_a0)/2 at Z = 0 cut 35·(1/cos 6.5° − 1) =
    0.227 mm below the root over the whole face. The last cut now touches the root cone."""
    report = simulated(conn, monkeypatch, 50, Choices())
    assert not report.refusals, "\n".join(report.lines())
    assert abs(report.cuts[-1].stock_left) <= 0.01


def test_instantiate_stores_only_programs_the_simulation_proves(conn):
    for gear_id in (42, 43, 44, 45, 46, 47, 50, 51, 53, 54):   # every seeded gear gets a program
        program = instantiate_gear(conn, gear_id)
        assert not simulate_stored_program(conn, program.program_id).refused


def test_a_hobbing_program_without_its_gear_and_hob_is_not_stored(conn):
    machine = load_machine(conn, MACHINE)
    with pytest.raises(EngineError, match="gear and hob"):
        verified_run.prove(["%_N_X_MPF", "M30"], machine, None, "X")


def test_engine_simulate_prints_what_the_library_says_and_exits_1_when_refused(run, monkeypatch):
    with monkeypatch.context() as patch:
        patch.setattr(verified_run, "prove", lambda *args, **kwargs: None)
        assert run("instantiate", "--gear", 42).exit_code == 0
    import psycopg
    with psycopg.connect(run.url) as conn:
        program_id = conn.execute("SELECT max(id) FROM program").fetchone()[0]
        report = simulate_stored_program(conn, program_id)
    text = run("simulate", "--program", program_id)
    assert text.exit_code == (1 if report.refused else 0)
    assert text.stdout.splitlines() == report.lines()
    payload = run("simulate", "--program", program_id, "--json")
    assert len(payload.stdout.splitlines()) == 1 and json.loads(payload.stdout)["refused"] == report.refused
    missing = run("simulate", "--program", 999999)
    assert missing.exit_code == 1 and "program 999999 does not exist" in missing.stderr
    assert "Example: engine simulate" in run("simulate", "--help").stdout
