"""Helical tapers on a polyline pass (issue 29): the hob centre that keeps a swivelled hob's tip
cylinder tangent to the root cone is not on the straight line X(0) + Z·tan δ (§B12).

Computed here from the reference geometry, not from engine code: the hob is a cylinder of
radius d_a0/2 and length L swivelled by A = h_hob·γ − h_gear·β (§A7) about X, the root is the
cone d_f2/2 + Z·tan δ continued beyond the faces, and how deep a standing hob reaches into it
(negative: short of it) is tests/helpers/hobbing_envelope.intrusion, proven within 1e-6 mm.
For each gear below the straight line through the program's own top-face X misses the cone by
more than the simulation's 0.01 mm (stock or root cut): the straight pass the engine wrote
before, which the simulation refused (shown by simulating it), while the polyline it writes now
touches the cone at every vertex within that tolerance and is proved.
"""
from __future__ import annotations

import math
import re

import pytest
from helpers.hobbing_checks import Case, Job
from helpers.hobbing_envelope import Solid, Sweep, intrusions
from helpers.hobbing_machine_checks import all_problems
from helpers.hobbing_reference import Gear, Move, Unit, read, swivel
from helpers.hobbing_reference_gears import (
    DIN,
    STOCK,
    cylindrical,
    insert_gear,
    insert_hob,
    make_hob,
    only_hob,
    read_holding,
    read_machine,
)

from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program

TOLERANCE = 0.01   # mm: the simulation's stock above, and cut below, the intended root
GEAR_ID = 9380

# module, teeth, β, gear hand, hob hand, hob starts, δ, face width
CASES = [   # each off by 0.02–0.04 mm on the straight line at the bottom face (the first test)
    (2.0, 45, 30.0, "L", "L", 1, 12.0, 25.0),
    (2.0, 25, 30.0, "R", "L", 1, 10.0, 30.0),
    (2.0, 40, 25.0, "L", "R", 1, -10.0, 30.0),
    (3.0, 22, 20.0, "R", "L", 2, 12.0, 36.0),
    (3.0, 35, 20.0, "L", "R", 1, -12.0, 36.0),
    (3.0, 50, 30.0, "L", "L", 1, -10.0, 40.0),
    (4.0, 28, 25.0, "L", "R", 1, 10.0, 44.0),
    (4.0, 40, 15.0, "R", "L", 1, -12.0, 48.0),
]
IDS = [f"m{c[0]:g}-z{c[1]}-b{c[2]:g}{c[3]}-hob{c[4]}{c[5]}-d{c[6]:+g}" for c in CASES]


def gear_of(case) -> tuple[Gear, object]:
    mn, z2, beta, hand, hob_hand, starts, cone, width = case
    return Gear("taper", mn, beta, hand, (Unit(z2, width, *cylindrical(mn, z2, beta)),), cone=cone), \
        make_hob(mn, hob_hand, starts)


def root_cone(gear: Gear) -> Solid:
    """The root d_f2/2 + Z·tan δ, continued far beyond both faces (no face limits the depth)."""
    return Solid(gear.first.df / 2, -1e4, 1e4, math.tan(math.radians(gear.cone)), 0.0)


def depths(gear: Gear, hob, centres: list[tuple[float, float]]) -> list[float]:
    """How far the standing hob at each (X, Z) reaches into the root cone (mm, < 0: short of it)."""
    sweeps = [Sweep(x, z, x, z, swivel(gear, hob)) for x, z in centres]
    return [float(d) for d in intrusions(sweeps, [root_cone(gear)] * len(sweeps), hob.r0, hob.length)]


def last_pass(nc) -> list[Move]:
    """The last cut's pass: the G1 moves along Z after the last radial infeed."""
    moves = [m for m in nc.moves if m.mode == "G1"]
    infeeds = [i for i, m in enumerate(moves) if m.delta("Z") == 0 and m.delta("X") != 0]
    return [m for m in moves[infeeds[-1] + 1:] if m.delta("Z") != 0]


def straight_program(text: str, slope: float) -> str:
    """The program as the engine wrote it before: each pass (the G1 blocks after an infeed) one G1
    along X(0) + Z·tan δ through the pass's own X at the top face Z = 0, F the slant feed, its
    infeed to that line at the approach Z."""
    lines, out, index = text.splitlines(), [], 0
    while index < len(lines):
        infeed = re.fullmatch(r"G1 X(\S+) F(\S+)", lines[index])
        if not infeed:
            out.append(lines[index])
            index += 1
            continue
        z = float(re.search(r"G0 Z(\S+)", "\n".join(out[-3:])).group(1))
        x, vertices, feed = float(infeed.group(1)), [], None
        vertices.append((x, z))
        index += 1
        while index < len(lines) and not lines[index].startswith("G0"):
            words = dict(re.findall(r"([XZF])(-?[\d.]+)", lines[index])) if lines[index].startswith("G1") else {}
            x, z = float(words.get("X", x)), float(words.get("Z", z))
            feed = words["F"] if {"X", "Z", "F"} <= words.keys() else feed
            vertices.append((x, z))
            index += 1
        top = next(x0 + (0 - z0) * (x1 - x0) / (z1 - z0)
                   for (x0, z0), (x1, z1) in zip(vertices, vertices[1:]) if z0 != z1 and min(z0, z1) <= 0 <= max(z0, z1)
                   )
        z_from, z_to = vertices[0][1], vertices[-1][1]
        out += [f"G1 X{top + z_from * slope:.3f} F{infeed.group(2)}",
                f"G1 X{top + z_to * slope:.3f} Z{z_to:.3f} F{feed}"]
    return "\n".join(out)


def made(conn, case):
    gear, hob = gear_of(case)
    only_hob(conn, insert_hob(conn, hob, gear.mn))
    insert_gear(conn, GEAR_ID, gear, 0.0, STOCK)
    return gear, hob, instantiate_gear(conn, GEAR_ID)   # stored only once the simulation proves it


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_the_straight_line_misses_the_root_cone_of_a_helical_taper(case):
    """Independently of any program: the hob tangent to the cone at the top face, moved along
    X(0) + Z·tan δ, is more than the tolerance off the cone at the bottom face."""
    gear, hob = gear_of(case)
    slope = math.tan(math.radians(gear.cone))
    x0 = tangent_x(gear, hob, 0.0)
    bottom = -gear.first.b
    error = depths(gear, hob, [(x0 + bottom * slope, bottom)])[0]
    assert abs(error) > TOLERANCE, f"the straight line is only {error:+.4f} mm off the root cone at the bottom face"


def tangent_x(gear: Gear, hob, z: float) -> float:
    """X at which the standing hob at height z just touches the root cone (bisection on depth = 0)."""
    low, high = gear.first.df / 2 + z * math.tan(math.radians(gear.cone)), gear.first.df / 2 + 3 * hob.r0
    while high - low > 1e-5:
        middle = (low + high) / 2
        low, high = (middle, high) if depths(gear, hob, [(middle, z)])[0] > 0 else (low, middle)
    return (low + high) / 2


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_a_helical_taper_is_made_on_a_polyline_tangent_to_the_root_cone(conn, case):
    """The program is stored (the simulation proved it); its last pass, read from the text,
    touches the root cone at every vertex; the straight pass through the same top-face X is
    refused by the simulation; and the reference checks of issue 14 find nothing."""
    with conn.transaction(force_rollback=True):
        gear, hob, program = made(conn, case)
        machine, holding = read_machine(conn, DIN.name), read_holding(conn, program.text)
        engine_gear, engine_machine = load_gear(conn, GEAR_ID), load_machine(conn, DIN.name)
        engine_hob = next(h for h in load_hobs(conn) if h.id == hob_id(program))
    report = simulate_program(program.lines, engine_gear, engine_hob, engine_machine, program.name)
    assert not report.refusals, "\n".join(report.lines())
    old = straight_program(program.text, math.tan(math.radians(gear.cone)))
    refused = simulate_program(old.splitlines(), engine_gear, engine_hob, engine_machine, program.name)
    assert refused.refusals, "the straight pass was proved: this gear does not need the polyline\n" + old
    nc = read(program.text)
    pass_moves = last_pass(nc)
    assert len(pass_moves) >= 12, "a pass of a few segments cannot follow the curved centre path"
    assert pass_moves[0].start["Z"] > 0 > -gear.first.b > pass_moves[-1].end["Z"], "the pass crosses both faces"
    slanted = [m for m in pass_moves if m.delta("X") != 0]   # beyond the faces X may be held, above the cone
    centres = [(m.start["X"], m.start["Z"]) for m in slanted] + [(slanted[-1].end["X"], slanted[-1].end["Z"])]
    off = [(x, z, round(d, 4)) for (x, z), d in zip(centres, depths(gear, hob, centres)) if abs(d) > TOLERANCE]
    assert not off, f"vertices (X, Z, depth) off the root cone: {off}"
    problems = all_problems(nc, Case(gear, hob, machine, Job(), holding))
    assert not problems, "\n".join(problems)


def hob_id(program) -> str:
    return next(line.split()[2] for line in program.lines if line.startswith("; HOB "))
