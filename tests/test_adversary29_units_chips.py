"""Adversary 29: a cluster gear's feed mode per unit and the chip-thickness bound, attacked.

A program reaches the machine only proved; the header's `; n0=… cuts=<c> <mode>` says how each
unit is fed (climb: down, −Z DIN; conventional: up, reference §B13), so a program whose passes
go another way than its header says must be refused. The forged programs below are the engine's
own for the seeded cluster gear 54 (m2, unit 1 z30 Ø64 b20 at Z0, unit 2 z19 b15 at Z−75, made
`--feed-mode climb/conventional`) edited as an editor or a template row could: each stays a
program the machine runs, and each says something its moves do not do. What the moves do is
read here from the G1 Z words (which unit a pass is in by its Z range), never from the engine.

The chip bound (reference §C1, Hoffmeister) is computed here term by term, with the depth of cut
T the gear's whole tooth depth (d_a − d_f)/2 as the record gives it: a gear hobbed for grinding
has a dedendum of 1.4·m_n (ISO 53 profile D), T = 2.4·m_n, not the standard 2.25·m_n."""
from __future__ import annotations

import json
import math
import re

import psycopg
import pytest
from helpers.collision_truth import messages

from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program

MACHINE = "hobber-840d"
CLUSTER = 54
UNIT_1 = (0.0, -20.0)        # gear 54's unit 1: top face Z0, 20 mm wide
UNIT_2 = (-75.0, -90.0)      # its unit 2 (gear_unit): top face Z−75, 15 mm wide
Z_WORD = re.compile(r"\bZ(-?[0-9.]+)")
F_WORD = re.compile(r"\bF([0-9.]+)")


def simulated(conn, gear_id: int, lines: list[str]):
    hob_id = next(line.split()[2] for line in lines if line.startswith("; HOB "))
    hob = next(hob for hob in load_hobs(conn) if hob.id == hob_id)
    return simulate_program(lines, load_gear(conn, gear_id), hob, load_machine(conn, MACHINE), f"GEAR{gear_id}")


def cluster_program(conn) -> str:
    program = instantiate_gear(conn, CLUSTER, choices=Choices(feed_mode="climb/conventional"))
    text = "\n".join(program.lines)
    assert simulated(conn, CLUSTER, program.lines).refusals == []
    return text


def passes(text: str) -> list[tuple[str, str]]:
    """(unit, "down"/"up") of every G1 move along Z longer than 1 mm, in program order, the unit
    being the one whose faces the move's Z range overlaps."""
    found, z = [], None
    for line in text.split("\n"):
        word = Z_WORD.search(line) if line.startswith(("G0", "G1")) else None
        if word is None:
            continue
        new = float(word.group(1))
        if line.startswith("G1") and z is not None and abs(new - z) > 1.0:
            low, high = min(z, new), max(z, new)
            unit = "unit 1" if low < UNIT_1[0] and high > UNIT_1[1] else "unit 2"
            found.append((unit, "down" if new < z else "up"))
        z = new
    return found


def header_mode(text: str) -> str:
    return next(line.split()[-1] for line in text.split("\n") if line.startswith("; n0="))


def said_per_unit(mode: str) -> dict:
    """The direction the header's mode gives each unit's single cut (§B13: climb down)."""
    modes = mode.split("/")
    return {f"unit {n}": "down" if modes[min(n, len(modes)) - 1].split("-")[0] == "climb" else "up" for n in (1, 2)}


def header_lies(text: str) -> bool:
    said = said_per_unit(header_mode(text))
    return any(said[unit] != direction for unit, direction in passes(text))


def with_header(text: str, mode: str) -> str:
    return text.replace("cuts=1 climb/conventional", f"cuts=1 {mode}")


def test_the_engines_program_says_what_it_does(conn):
    text = cluster_program(conn)
    assert passes(text) == [("unit 1", "down"), ("unit 2", "up")]
    assert not header_lies(text)


def test_a_program_without_cut_comments_is_not_proved_on_its_header_alone(conn):
    """Without `; CUT` comments nothing held the header's feed mode to the passes: unit 1 fed
    down and unit 2 up, said `conventional/climb`, was proved."""
    text = cluster_program(conn)
    forged = "\n".join(line for line in with_header(text, "conventional/climb").split("\n")
                       if not line.startswith("; CUT "))
    assert header_lies(forged)
    assert messages(simulated(conn, CLUSTER, forged.split("\n")))


def test_a_pass_fed_up_after_a_micron_down_is_not_a_climb_cut(conn):
    """The first Z move after `; CUT` gave the cut's direction: 1 µm down in air before unit 2's
    38 mm pass up made it CLIMB, and the header `climb` was proved for a conventional pass."""
    text = cluster_program(conn)
    pass_2 = next(line for line in text.split("\n") if line.startswith("G1 X51.5"))
    start = next(line for line in text.split("\n") if line.startswith("G0 Z-109"))
    below = float(Z_WORD.search(start).group(1)) - 0.001
    forged = (with_header(text, "climb").replace(" X=51.500 CONVENTIONAL", " X=51.500 CLIMB")
              .replace(pass_2, f"{pass_2}\nG1 Z{below:.3f}"))
    assert header_lies(forged)
    found = messages(simulated(conn, CLUSTER, forged.split("\n")))
    assert found, "a conventional pass said climb was proved"


def test_an_axial_pass_said_tangential_is_refused(conn):
    """TANGENTIAL was any cut that moved Y: a 1 µm Y move with the table uncoupled let unit 2's
    pass up escape the header's `climb` (a spur gear's pass along Z is never tangential)."""
    text = cluster_program(conn)
    lines = text.split("\n")
    comment = next(line for line in lines if line.startswith("; CUT ") and line.endswith("CONVENTIONAL"))
    egon = next(line for line in lines if line.startswith("EGON(") and line.endswith(",19)"))
    forged = (with_header(text, "climb").replace(comment + "\n", "")
              .replace(egon, comment.replace("CONVENTIONAL", "TANGENTIAL") + "\nG1 Y0.001 F100\nG1 Y0\n" + egon))
    assert header_lies(forged)
    assert messages(simulated(conn, CLUSTER, forged.split("\n")))


def test_the_units_cut_in_the_other_order_keep_their_own_modes(conn):
    """The mode per unit was matched to the `; CUT` comments by their order: unit 2 cut first
    (conventional, up) and then unit 1 (climb, down), said `conventional/climb` (unit 1
    conventional), was proved."""
    text = cluster_program(conn)
    unit_1 = text[text.index('EGON(C,"FINE",B,-1,30)'):text.index("; UNIT 2")]
    between = text[text.index("; UNIT 2"):text.index('EGON(C,"FINE",B,-1,19)')]
    unit_2 = text[text.index('EGON(C,"FINE",B,-1,19)'):text.index("M9\n")]
    head, tail = text[:text.index('EGON(C,"FINE",B,-1,30)')], text[text.index("M9\n"):]
    unit_line_2 = between.split("\n")[0]
    forged = (head + unit_2.replace("M3 S310\n", "M3 S310\nM8\n", 1) + between.replace(unit_line_2 + "\n", "")
              + unit_1.replace("M8\n", "").replace("; UNIT 1", unit_line_2 + "\n; UNIT 1") + tail)
    forged = with_header(forged, "conventional/climb")
    assert passes(forged) == [("unit 2", "up"), ("unit 1", "down")] and header_lies(forged)
    found = messages(simulated(conn, CLUSTER, forged.split("\n")))
    assert any("the header states feed mode conventional/climb" in message for message in found), found


@pytest.mark.parametrize("stored", [5, ["climb"], {"unit": "climb"}])
def test_a_stored_feed_mode_not_a_word_is_refused_in_one_line(run, stored):
    """A shop edits job.params in SQL; a feed mode stored as a number or a list crashed the
    remake (exit 2, AttributeError)."""
    made = run("instantiate", "--gear", 42, "--json")
    job_id = json.loads(made.stdout)["job_id"]
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE job SET params = jsonb_set(params, '{feed_mode}', %s::jsonb) WHERE id = %s",
                     (json.dumps(stored), job_id))
    result = run("instantiate", "--job", job_id, "--dry-run")
    assert result.exit_code == 1, result.output
    assert result.stderr.count("\n") == 1 and "feed mode" in result.stderr, result.stderr


# Hoffmeister (reference §C1), written out here with the depth of cut as a parameter.
def h_max(module, teeth, tip_of_hob, gashes, starts, feed, depth) -> float:
    return (4.9 * module * teeth ** -0.542 * (tip_of_hob / 2 / module) ** -0.225 * (gashes / starts) ** -0.877
            * (feed / module) ** 0.511 * (depth / module) ** 0.319)


GRIND = 45                     # m4 z25 spur, d_a 108, hob H-M4-A-R1 (d_a0 90, 12 gashes, 1 start)
GRIND_ROOT = 108 - 2 * (4 + 1.4 * 4)     # dedendum 1.4·m_n (ISO 53 profile D): d_f 88.8
GRIND_DEPTH = (108 - GRIND_ROOT) / 2     # T = 9.6 mm = 2.4·m_n


def axial_feeds(lines: list[str], teeth: int, starts: int) -> list[float]:
    """f_a [mm per workpiece revolution] of every G1 Z pass: F over the table speed n0·z0/z2."""
    n0 = next(int(line.split("=")[1].split()[0]) for line in lines if line.startswith("; n0="))
    table, feed, found = n0 * starts / teeth, 0.0, []
    for line in lines:
        word = F_WORD.search(line) if line.startswith("G1") else None
        feed = float(word.group(1)) if word else feed
        if line.startswith("G1") and Z_WORD.search(line):
            found.append(feed / table)
    return found


def test_a_gear_cut_deeper_than_2_25_modules_keeps_its_chips_within_the_bound(conn):
    """The bound took T = 2.25·m_n whatever the record: gear 45 with d_f 88.8 (T 9.6 mm) roughed at
    1.92 mm/rev, chips of 0.204 mm."""
    conn.execute("UPDATE gear SET root_diameter = %s WHERE id = %s", (GRIND_ROOT, GRIND))
    lines = instantiate_gear(conn, GRIND, choices=Choices(cuts=2)).lines
    chips = [h_max(4, 25, 90, 12, 1, feed, GRIND_DEPTH) for feed in axial_feeds(lines, 25, 1)]
    assert chips and max(chips) <= 0.20 * (1 + 1e-6), chips


def test_the_simulation_refuses_a_pass_above_the_bound_of_the_records_depth(conn):
    """The simulation reads the F word and the records: a rough pass at the feed the standard depth
    would allow (F21.7 at 11.32 r/min of the table: 1.917 mm/rev, chips of 0.204 mm at T 9.6 mm)
    is above the bound of this gear."""
    conn.execute("UPDATE gear SET root_diameter = %s WHERE id = %s", (GRIND_ROOT, GRIND))
    lines = instantiate_gear(conn, GRIND, choices=Choices(cuts=2)).lines
    n0 = next(int(line.split("=")[1].split()[0]) for line in lines if line.startswith("; n0="))
    table = n0 / 25
    standard_bound = 4 * (0.20 / h_max(4, 25, 90, 12, 1, 4, 9.0)) ** (1 / 0.511)   # T = 2.25·m_n
    fast = math.floor(standard_bound * table * 10) / 10
    assert h_max(4, 25, 90, 12, 1, fast / table, GRIND_DEPTH) > 0.20
    rough = next(index for index, line in enumerate(lines) if line.startswith("G1") and Z_WORD.search(line))
    forged = list(lines)
    forged[rough] = F_WORD.sub(f"F{fast:.1f}", lines[rough])
    found = messages(simulated(conn, GRIND, forged))
    assert any("Hoffmeister" in message for message in found), found


def test_a_slip_in_the_planners_chip_bound_is_not_proved(conn, monkeypatch):
    """The simulation held passes to the planner's own chip bound (engine.gears.cutting_data's
    chip_feed_bound): a planner whose bound were twice the formula's would rough gear 45 at the
    history's 3.5 mm/rev, chips of 0.27 mm, and the simulation proved it. It works h_max out itself."""
    import engine.gears.cutting_data as cutting_data
    from engine.errors import EngineError

    true_bound = 4 * (0.20 / h_max(4, 25, 90, 12, 1, 4, 9.0)) ** (1 / 0.511)
    assert h_max(4, 25, 90, 12, 1, 3.5, 9.0) > 0.25 and true_bound < 3.5
    real = cutting_data.chip_feed_bound
    monkeypatch.setattr(cutting_data, "chip_feed_bound", lambda gear, hob: 2 * real(gear, hob))
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, GRIND, choices=Choices(cuts=2, feed_mode="climb"))
    assert "Hoffmeister" in str(refused.value) and "\n" not in str(refused.value), str(refused.value)


def test_a_tangential_pass_above_the_feed_bound_is_refused(run):
    """A tangential worm wheel's pass feeds along Y at its kind's axial feed, at most the §C
    roughing maximum for m3, 3.5 mm per workpiece revolution (one start). Neither the stored job's
    check nor the simulation bounded it: feed_tangential edited to 1.5× that was proved."""
    made = run("instantiate", "--gear", 53, "--worm-feed", "tangential", "--json")
    assert made.exit_code == 0, made.output
    job_id = json.loads(made.stdout)["job_id"]
    with psycopg.connect(run.url) as conn:
        n0, starts, teeth = conn.execute(
            "SELECT (j.params->>'n0')::float, h.starts, g.teeth FROM job j JOIN hob h ON h.id = j.hob_id "
            "JOIN gear g ON g.id = j.gear_id WHERE j.id = %s", (job_id,)).fetchone()
        fast = round(1.5 * 3.5 * n0 * starts / teeth, 1)   # mm/min: 1.5 × 3.5 mm/rev at n0·z0/z2
        conn.execute("UPDATE job SET module_params = jsonb_set(module_params, '{cutmotion:2,feed_tangential}', "
                     "%s::jsonb) WHERE id = %s", (json.dumps(fast), job_id))
    result = run("instantiate", "--job", job_id, "--dry-run")
    assert result.exit_code == 1, result.output
    assert result.stderr.count("\n") == 1 and "tangential" in result.stderr, result.stderr
