"""Issue 26: the hobbing facts the simulation holds a program to from its own text and the
records (gear, hob, machine), whatever job or model made it. Each test takes a genuine program
the seeded templates make, edits one line as a careless editor or runner would, and expects the
refusal at that line; the expected numbers come from the reference formulas (docs/reference/
hobbing.md §B4: v = π·d_a0·n0/1000, n2 = n0·z0/z2; §C the speed table), not from the engine."""
from __future__ import annotations

import math

import psycopg
import pytest

from engine.errors import EngineError
from engine.gears.hob_matching import HobChoice
from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from engine.programs import instantiate as instantiating
from engine.programs import verified_run
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.simulation import simulate_program
from engine.simulation.hobbing.report import SimulationError
from engine.verifier.program import verify_program
from engine.verifier.refusals import LimitError

MACHINE = "hobber-840d"
DRY = RunMode(dry_run=True)
COATED_HSS_ON_40CR = (50.0, 90.0)     # §C: TiN/TiAlN PM-HSS on 40Cr (Q&T), m/min


def genuine(conn, gear_id: int = 42) -> tuple[list[str], str]:
    """The program the seeded templates make for the gear (a dry run: the engine's own proof
    passed it), and its hob."""
    program = instantiate_gear(conn, gear_id, mode=DRY)
    hob_line = next(line for line in program.lines if line.startswith("; HOB "))
    return list(program.lines), hob_line.split()[2]


def records(conn, gear_id: int, hob_id: str):
    return load_gear(conn, gear_id), next(h for h in load_hobs(conn) if h.id == hob_id), load_machine(conn, MACHINE)


def refusals(conn, lines: list[str], gear_id: int, hob_id: str) -> dict[int, list[str]]:
    report = simulate_program(lines, *records(conn, gear_id, hob_id), "TEST")
    found: dict[int, list[str]] = {}
    for finding in report.refusals:
        found.setdefault(finding.number, []).append(finding.message)
    return found


def edited(lines: list[str], old: str, new: str) -> tuple[list[str], int]:
    """The lines with the first line `old` replaced by `new`, and its line number (from 1)."""
    at = lines.index(old)
    return lines[:at] + [new] + lines[at + 1:], at + 1


def inserted(lines: list[str], after: str, new: str) -> tuple[list[str], int]:
    at = lines.index(after) + 1
    return lines[:at] + [new] + lines[at:], at + 1


def spindle_line(lines: list[str]) -> str:
    return next(line for line in lines if line.startswith("M3 S"))


def header_n0(lines: list[str]) -> int:
    line = next(line for line in lines if line.startswith("; n0="))
    return int(line.split()[1].removeprefix("n0="))


def cutting_speed(tip_diameter: float, n0: float) -> float:
    """§B4: v = π·d_a0·n0/1000 m/min."""
    return math.pi * tip_diameter * n0 / 1000


# ---------------------------------------------------------------- finding 1: the hob fits the gear

def choosing(monkeypatch, conn, hob_id: str) -> None:
    """The planner takes `hob_id` whatever the gear (as a runner's job naming it would)."""
    hob = next(h for h in load_hobs(conn) if h.id == hob_id)
    monkeypatch.setattr(instantiating, "matching_hobs", lambda *args, **kwargs: [HobChoice(hob, "a runner's choice")])


@pytest.mark.parametrize("hob_id, module", [("H-M2.5-AA-R1", 2.5), ("H-M3-AA-R1", 3)])
def test_a_program_for_gear_42_made_with_a_hob_of_another_module_is_refused(conn, monkeypatch, hob_id, module):
    choosing(monkeypatch, conn, hob_id)
    gear = load_gear(conn, 42)
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, 42, mode=DRY)
    message = str(refused.value)
    assert f"hob {hob_id} does not fit gear 42" in message
    assert f"module {gear.module:g}" in message and f"module {module:g}" in message
    assert "'; HOB " in message     # the refusal names the program line that names the hob


@pytest.mark.parametrize("hob_id", ["H-M2.5-AA-R1", "H-M3-AA-R1"])
def test_a_runners_copied_job_naming_another_hob_is_refused_by_instantiate_and_simulate(run, monkeypatch, hob_id):
    with psycopg.connect(run.url) as conn:
        choosing(monkeypatch, conn, hob_id)      # the job and program as the planner would make them for that hob
        with monkeypatch.context() as unproved:
            unproved.setattr(verified_run, "prove", lambda *args, **kwargs: None)
            made = instantiate_gear(conn, 42)
        conn.commit()
        copied = conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params, cutting) "
                              "SELECT gear_id, gear_class, machine, hob_id, params, module_params, cutting FROM job "
                              "WHERE id = %s RETURNING id", (made.job_id,)).fetchone()[0]
        conn.commit()
        programs = conn.execute("SELECT count(*) FROM program").fetchone()[0]
    monkeypatch.undo()
    result = run("instantiate", "--job", copied)
    assert result.exit_code == 1, result.output
    assert f"hob {hob_id} does not fit gear 42" in result.output
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == programs   # nothing stored
    result = run("simulate", "--program", made.program_id)
    assert result.exit_code == 1, result.output
    assert f"hob {hob_id} does not fit gear 42" in result.output


# ---------------------------------------------------------------- finding 3: every hob speed within §C

def test_a_spindle_speed_four_times_n0_is_refused_with_its_cutting_speed(conn):
    lines, hob_id = genuine(conn)
    hob = records(conn, 42, hob_id)[1]
    lines, number = edited(lines, spindle_line(lines), "M3 S1000")
    found = refusals(conn, lines, 42, hob_id)
    v = cutting_speed(hob.tip_diameter, 1000)
    assert v > COATED_HSS_ON_40CR[1]
    assert any(f"{v:.1f} m/min, above the {COATED_HSS_ON_40CR[1]:g} m/min" in m for m in found[number]), found
    assert any(f"n0={header_n0(lines)}" in m for m in found[number]), found


def test_an_s_changed_mid_program_is_held_to_the_table_and_the_header(conn):
    lines, hob_id = genuine(conn)
    hob = records(conn, 42, hob_id)[1]
    n0 = header_n0(lines)
    assert COATED_HSS_ON_40CR[0] <= cutting_speed(hob.tip_diameter, n0) <= COATED_HSS_ON_40CR[1]
    lines, number = inserted(lines, spindle_line(lines), "M3 S1000")
    found = refusals(conn, lines, 42, hob_id)
    assert any(f"{cutting_speed(hob.tip_diameter, 1000):.1f} m/min" in m for m in found[number]), found


def test_an_s_within_the_table_but_not_the_headers_n0_is_refused(conn):
    lines, hob_id = genuine(conn)
    hob = records(conn, 42, hob_id)[1]
    speed = math.floor(1000 * COATED_HSS_ON_40CR[1] / (math.pi * hob.tip_diameter))   # the table's fastest
    assert speed != header_n0(lines)
    lines, number = edited(lines, spindle_line(lines), f"M3 S{speed}")
    found = refusals(conn, lines, 42, hob_id)
    assert found.keys() == {number}, found
    assert [m for m in found[number] if "m/min" in m] == []
    assert any(f"the header states n0={header_n0(lines)}" in m for m in found[number]), found


def test_a_gear_material_of_the_table_takes_its_row_and_no_material_the_widest_as_a_note(conn):
    lines, hob_id = genuine(conn, 53)          # CuSn12: a row of table material (reference §C2, issue 31)
    report = simulate_program(lines, *records(conn, 53, hob_id), "TEST")
    assert not report.refusals, report.lines()
    assert not any("widest" in f.message for f in report.findings), report.lines()
    conn.execute("UPDATE gear SET material = NULL WHERE id = 53")   # rolled back with the test
    report = simulate_program(lines, *records(conn, 53, hob_id), "TEST")
    assert not report.refusals, report.lines()
    assert any("no material" in f.message and "widest" in f.message for f in report.findings if not f.refuses)


# ---------------------------------------------------------------- finding 4: the tailstock clamped in every cut

@pytest.mark.parametrize("where", ["before the cut", "between infeed and pass"])
def test_the_tailstock_released_before_or_during_the_cut_is_refused(conn, where):
    lines, hob_id = genuine(conn)
    infeed = next(i for i, line in enumerate(lines) if line.startswith("G1 X"))
    after = lines[infeed - 1] if where == "before the cut" else lines[infeed]
    lines, released = inserted(lines, after, "M21")
    found = refusals(conn, lines, 42, hob_id)
    cut = next(i for i, line in enumerate(lines, start=1) if i > released and line.startswith("G1 "))
    assert any(f"tailstock released by M21 at line {released}" in m for m in found[cut]), found


# ---------------------------------------------------------------- finding 5: EGON waits, the working area is set once

def test_egon_without_waiting_for_synchronism_is_refused_by_the_verifier_and_the_simulation(conn):
    lines, hob_id = genuine(conn)
    egon = next(line for line in lines if line.startswith("EGON("))
    lines, number = edited(lines, egon, egon.replace('"FINE"', '"NOC"'))
    gear, hob, machine = records(conn, 42, hob_id)
    with pytest.raises(LimitError, match=rf'line {number} .*"FINE"'):
        verify_program(lines, machine, "GEAR42")
    with pytest.raises(SimulationError, match=rf'line {number} .*"FINE"'):
        simulate_program(lines, gear, hob, machine, "GEAR42")


@pytest.mark.parametrize("limit", ["G25 X20.000 Y-80.000 Z-350.000", "G26 X320.000 Y80.000 Z150.000"])
def test_the_working_area_widened_after_the_start_is_refused_by_both(conn, limit):
    lines, hob_id = genuine(conn)
    first_move = next(line for line in lines if line.startswith("G0 "))
    lines, number = inserted(lines, first_move, limit)
    gear, hob, machine = records(conn, 42, hob_id)
    with pytest.raises(LimitError, match=rf"line {number} .*working area is set once"):
        verify_program(lines, machine, "GEAR42")
    assert any("working area is set once" in m for m in refusals(conn, lines, 42, hob_id)[number])


# ---------------------------------------------------------------- finding 6: what the header states is true

def header_lies(gear, hob, n0: int) -> list[tuple[str, str, str]]:
    """(line the templates write, the lie, what the refusal says), from the records."""
    table = n0 * hob.starts / gear.teeth       # §B4: n2 = n0·z0/z2
    return [
        (f"; GEAR 42 CLASS spur m={gear.module:g} z={gear.teeth} beta=0", "; GEAR 42 CLASS spur m=-8 z=19 beta=0",
         f"has m={gear.module:g}"),
        (f"; GEAR 42 CLASS spur m={gear.module:g} z={gear.teeth} beta=0",
         f"; GEAR 42 CLASS spur m={gear.module:g} z=20 beta=0", f"has z={gear.teeth}"),
        (f"; GEAR 42 CLASS spur m={gear.module:g} z={gear.teeth} beta=0",
         f"; GEAR 42 CLASS helical m={gear.module:g} z={gear.teeth} beta=0", "class spur"),
        (f"; HOB {hob.id} z0={hob.starts} da0={hob.tip_diameter:g} hand={hob.hand}",
         f"; HOB {hob.id} z0=-9 da0=0 hand={hob.hand}", f"has z0={hob.starts}"),
        (f"; HOB {hob.id} z0={hob.starts} da0={hob.tip_diameter:g} hand={hob.hand}",
         f"; HOB {hob.id} z0={hob.starts} da0=0 hand={hob.hand}", f"has da0={hob.tip_diameter:g}"),
        (f"; n0={n0} r/min table={table:.3f} r/min cuts=1 climb", f"; n0={n0} r/min table=20.000 r/min cuts=1 climb",
         f"{table:.3f} r/min"),
        (f"; n0={n0} r/min table={table:.3f} r/min cuts=1 climb",
         f"; n0={n0} r/min table={table:.3f} r/min cuts=2 climb", "cuts=2"),
        (f"; n0={n0} r/min table={table:.3f} r/min cuts=1 climb",
         f"; n0={n0} r/min table={table:.3f} r/min cuts=1 conventional", "feed mode conventional"),
    ]


@pytest.mark.parametrize("lie", range(8))
def test_a_header_fact_other_than_the_records_is_refused_at_its_line(conn, lie):
    lines, hob_id = genuine(conn)
    gear, hob, _ = records(conn, 42, hob_id)
    line, lie_line, said = header_lies(gear, hob, header_n0(lines))[lie]
    lines, number = edited(lines, line, lie_line)
    found = refusals(conn, lines, 42, hob_id)
    assert any(said in m for m in found.get(number, [])), found


def test_conventional_written_on_a_climb_pass_is_refused(conn):
    """§B13: the hob turning in its cutting direction under M3 meets the work with its teeth
    moving up (the DIN frame), so a pass feeding down (Z falling) is climb."""
    lines, hob_id = genuine(conn)
    cut = next(line for line in lines if line.startswith("; CUT ") and line.endswith(" CLIMB"))
    pass_z = [float(line.split()[1][1:]) for line in lines if line.startswith("G1 Z")]
    start_z = float(next(line for line in lines[lines.index(cut):] if line.startswith("G0 Z")).split()[1][1:])
    assert pass_z[0] < start_z                   # the genuine pass feeds down
    lines, number = edited(lines, cut, cut.removesuffix("CLIMB") + "CONVENTIONAL")
    found = refusals(conn, lines, 42, hob_id)
    assert any("said CONVENTIONAL but feeds down" in m for m in found[number]), found


def test_a_duplex_units_header_is_held_to_its_unit_record(conn):
    lines, hob_id = genuine(conn, 54)
    unit = load_gear(conn, 54).units[0]
    line = next(line for line in lines if line.startswith(f"; UNIT {unit.unit} "))
    lines, number = edited(lines, line, line.replace(f"z={unit.teeth}", f"z={unit.teeth + 1}"))
    found = refusals(conn, lines, 54, hob_id)
    assert any(f"has z={unit.teeth}" in m for m in found[number]), found


@pytest.mark.parametrize("gear_id", [42, 43, 44, 45, 46, 47, 50, 51, 53, 54])
def test_every_seeded_gears_genuine_program_states_only_true_facts(conn, gear_id):
    lines, hob_id = genuine(conn, gear_id)
    assert refusals(conn, lines, gear_id, hob_id) == {}


@pytest.mark.parametrize("written", ["; n0 = 900 r/min", "; n0=246 r/min table=12.947 r/min  cuts=1 climb",
                                     "; cut single climb", "; UNIT 2 z=20"])
def test_a_header_fact_written_another_way_is_refused_not_left_unchecked(conn, written):
    lines, hob_id = genuine(conn)
    lines, number = inserted(lines, next(line for line in lines if line.startswith("; n0=")), written)
    assert any("canonical whole-line form" in m for m in refusals(conn, lines, 42, hob_id)[number])
