"""A cluster gear whose units reach into each other is fed into the gap from both sides (issue 29:
"the engine never tries the feed direction ... that would fit"). One feed mode for both units
makes one of them enter from the gap, where the full run-in E = √(h·(d_a0 − h)) + 2 mm (reference
§B7) must fit between the faces besides the hob's reach into the other unit; feeding unit 1 down
(climb) and unit 2 up (conventional), both passes leave into the gap, where a run-out of about a
millimetre past the face is enough. The header states the mode per unit (`climb/conventional`:
unit 1's/unit 2's) and the simulation holds every cut to its unit's word.

The layout is the seeded duplex gear 54 (m2, unit 1 z30 Ø64 b20 at Z0) with unit 2 made z28 Ø60
and moved to GAP mm below unit 1. The reach is a lower bound computed here: the unswivelled hob's
tip circle (radius r0 about the cut's centre distance a = (d_f + d_a0)/2) inside the other unit's
tip radius plus the 1 mm clearance, √(r0² − (a − r_other − 1)²)."""
from __future__ import annotations

import math

import pytest
from helpers.collision_truth import messages
from helpers.nc_reader import read_program

from engine.errors import EngineError
from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program

GEAR = 54
MODULE = 2.0
UNIT_1 = {"tip": 64.0, "root": 64.0 - 4.5 * MODULE, "b": 20.0}
UNIT_2 = {"teeth": 28, "tip": 60.0, "root": 60.0 - 4.5 * MODULE, "b": 15.0}
HOB_TIP = 70.0           # every seeded m2 hob
CLEARANCE = 1.0          # mm the engine keeps between the hob and the other unit (design notes §7)
SAFETY = 2.0             # mm added to the run-in (§B7: 1–3 mm)
GAP = 28.0               # mm between the faces (the physics below)


def reach(cut_root: float, other_tip: float) -> float:
    """Lower bound of how far along Z the hob cutting a unit of root Ø cut_root reaches into the
    other unit of tip Ø other_tip, clearance included."""
    r0, centre = HOB_TIP / 2, (cut_root + HOB_TIP) / 2
    inside = centre - (other_tip / 2 + CLEARANCE)
    return math.sqrt(r0 ** 2 - inside ** 2) if inside < r0 else 0.0


def run_in(unit: dict) -> float:
    """§B7: E = √(h·(d_a0 − h)) + safety, h the unit's full tooth depth."""
    depth = (unit["tip"] - unit["root"]) / 2
    return math.sqrt(depth * (HOB_TIP - depth)) + SAFETY


def into_unit_1() -> float:
    return reach(UNIT_2["root"], UNIT_1["tip"])


def into_unit_2() -> float:
    return reach(UNIT_1["root"], UNIT_2["tip"])


def set_layout(conn) -> None:
    conn.execute("UPDATE gear_unit SET teeth = %s, tip_diameter = %s, root_diameter = NULL, z_top = %s "
                 "WHERE gear_id = %s", (UNIT_2["teeth"], UNIT_2["tip"], -UNIT_1["b"] - GAP, GEAR))


def passes(text: str) -> tuple[list, list]:
    """The axial passes (G1 in Z only) of unit 1 (above its bottom face) and of unit 2 (below the gap)."""
    moves = [m for m in read_program(text).moves_in("G1") if m.changed == {"Z"}]
    unit_1 = [m for m in moves if min(m.start["Z"], m.end["Z"]) > -UNIT_1["b"] - GAP]
    unit_2 = [m for m in moves if max(m.start["Z"], m.end["Z"]) < -UNIT_1["b"]]
    return unit_1, unit_2


def test_the_layout_is_one_no_single_mode_fits_and_each_unit_its_own_does():
    """The physics, independent of the engine: both units reach into each other; either single
    mode has one unit enter from the gap and needs more than GAP, leaving into it from both
    sides needs less (run-out 1 mm, and 1.5 mm for the swivel of a 100 mm hob at 1.8°)."""
    assert into_unit_1() > 0 and into_unit_2() > 0
    climb = run_in(UNIT_2) + into_unit_1()          # unit 2 fed down enters at its top face
    conventional = run_in(UNIT_1) + into_unit_2()   # unit 1 fed up enters at its bottom face
    each_its_own = max(into_unit_1(), into_unit_2()) + 1.0 + 50 * math.sin(math.asin(MODULE / (HOB_TIP - 5)))
    assert min(climb, conventional) > GAP > each_its_own + 1.0


def test_the_units_are_fed_toward_each_other_and_the_program_says_so(conn):
    set_layout(conn)
    program = instantiate_gear(conn, GEAR)
    text = "\n".join(program.lines)
    unit_1, unit_2 = passes(text)
    assert unit_1 and all(m.end["Z"] < m.start["Z"] for m in unit_1), "unit 1 climb: fed down"
    assert unit_2 and all(m.end["Z"] > m.start["Z"] for m in unit_2), "unit 2 conventional: fed up"
    assert min(m.end["Z"] for m in unit_1) < -UNIT_1["b"], "unit 1's pass leaves its bottom face"
    assert max(m.end["Z"] for m in unit_2) > -UNIT_1["b"] - GAP, "unit 2's pass leaves its top face"
    assert min(m.end["Z"] for m in unit_1) >= -UNIT_1["b"] - GAP + into_unit_2() - 0.001, "clear of unit 2"
    assert max(m.end["Z"] for m in unit_2) <= -UNIT_1["b"] - into_unit_1() + 0.001, "clear of unit 1"
    assert any(line.startswith("; n0=") and line.endswith(" climb/conventional") for line in program.lines)
    words = [line.split()[-1] for line in program.lines if line.startswith("; CUT ")]
    assert words == ["CLIMB", "CONVENTIONAL"], words
    note = next(note for note in program.notes if "not the first choice" in note)
    assert "cut with [climb/conventional, hob " in note
    stored = conn.execute("SELECT params->>'feed_mode' FROM job WHERE id = %s", (program.job_id,)).fetchone()
    assert stored == ("climb/conventional",)   # stored: proved by the verifier and the simulation


def simulated(conn, lines: list[str]):
    hob_id = next(line.split()[2] for line in lines if line.startswith("; HOB "))
    hob = next(hob for hob in load_hobs(conn) if hob.id == hob_id)
    return simulate_program(lines, load_gear(conn, GEAR), hob, load_machine(conn, "hobber-840d"), "GEAR54")


@pytest.mark.parametrize("stated", ["conventional/climb", "climb", "climb/conventional/climb", "climb/spiral"])
def test_a_header_misstating_the_units_feed_modes_is_refused(conn, stated):
    set_layout(conn)
    lines = instantiate_gear(conn, GEAR).lines
    forged = [line.replace(" climb/conventional", f" {stated}") if line.startswith("; n0=") else line
              for line in lines]
    assert simulated(conn, lines).refusals == []
    found = messages(simulated(conn, forged))
    assert any(f"the header states feed mode {stated}" in message for message in found), found


def test_a_mode_per_unit_on_a_gear_of_one_unit_is_refused_in_one_line(conn):
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, 42, choices=Choices(feed_mode="climb/conventional"))
    message = str(refused.value)
    assert "\n" not in message and "names one for each of 2 units; the gear has 1" in message, message


def test_a_feed_mode_not_known_is_refused_naming_the_modes(read_only_run):
    result = read_only_run("instantiate", "--gear", 54, "--feed-mode", "climb/sideways", "--dry-run")
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, result.stderr
    assert "climb/sideways" in result.stderr and "climb/conventional" in result.stderr
