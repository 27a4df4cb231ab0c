"""Duplex gears (two spur units on one blank, cut one after the other with the same hob): while
the hob cuts one unit, its envelope keeps clear of the other (issue 14 items 1 and 2, design
notes §7). Every valid layout gets a program or a one-line refusal (EngineError), never a crash.

The clearance is computed here from the geometry, independently of the engine: the hob is a
cylinder of radius d_a0/2 and length L (plus its shift either way) whose axis lies in the Y–Z
plane at the swivel η = γ (sin γ = z0·m/(d_a0 − 2.5·m), reference §B1, §B2); points on its
surface are tested against the neighbour unit, a cylinder of its tip radius over its face,
at hob centres sampled along the infeed (X from the retract position to the cut at the
approach Z), the axial pass and the retract (X back out at the end Z).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.hob_clearance import CUTTING, MACHINE, hob_surface, seeded_hobs
from helpers.nc_reader import read_program
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.gears.records import Gear, GearUnit, Hob
from engine.hobbing.choices import FEED_MODES, UNIT_FEED_MODES, Choices
from engine.hobbing.duplex import DuplexModel
from engine.programs.instantiate import instantiate_gear

MARGIN = 0.5            # mm: the least clearance a program may leave (the engine keeps more)
Z_STEP = 0.5            # mm between sampled hob centres along a pass


# ------------------------------------------------------------------ geometry, test side

def swivel(module: float, starts: int, hob_tip: float) -> float:
    """η = γ for a spur gear, sin γ = z0·m/(d_a0 − 2.5·m) (reference §B1, §B2), radians."""
    return math.asin(starts * module / (hob_tip - 2.5 * module))


def distance_to_unit(points: np.ndarray, radius: float, top: float, bottom: float) -> float:
    """Least signed distance of the points from a solid cylinder about the Z axis (negative inside)."""
    radial = np.hypot(points[:, 0], points[:, 1]) - radius
    axial = np.maximum(bottom - points[:, 2], points[:, 2] - top)
    outside = np.hypot(np.maximum(radial, 0), np.maximum(axial, 0))
    return float(np.min(outside + np.minimum(np.maximum(radial, axial), 0)))


def cut_centres(x_retract: float, cut_x: float, z_from: float, z_to: float) -> list[tuple[float, float]]:
    """Hob centres (X, Z) of one cut: infeed at z_from, the pass at cut_x, retract at z_to."""
    steps = max(2, int(abs(z_to - z_from) / Z_STEP) + 1)
    xs = np.linspace(cut_x, x_retract, 6)
    return ([(x, z_from) for x in xs] + [(cut_x, z) for z in np.linspace(z_from, z_to, steps)]
            + [(x, z_to) for x in xs])


def clearance(surface: np.ndarray, centres, unit: dict) -> float:
    """The least distance_to_unit of the hob at any of the centres (X, Z), the centres of one X
    taken together (issue 28: a pass has hundreds; this was most of the random test's time)."""
    heights_at: dict[float, list[float]] = {}
    for x, z in centres:
        heights_at.setdefault(float(x), []).append(float(z))
    return min(clearance_at_x(surface, x, zs, unit) for x, zs in heights_at.items())


def clearance_at_x(surface: np.ndarray, x: float, zs: list[float], unit: dict) -> float:
    """min over z in zs of distance_to_unit(surface + [x, 0, z], …), each point once: the signed
    distance grows with the axial distance at a given radial one, and the axial distance
    max(bottom − h, h − top) is least at the centre height that brings the point nearest the
    unit's mid-height, one of the two heights beside mid − (the point's own height)."""
    radius, top, bottom = unit["tip"] / 2, unit["top"], unit["top"] - unit["b"]
    radial = np.hypot(surface[:, 0] + x, surface[:, 1]) - radius
    heights, own = np.sort(np.asarray(zs + zs[-1:])), surface[:, 2]     # two heights at least
    beside = np.clip(np.searchsorted(heights, (top + bottom) / 2 - own), 1, heights.size - 1)
    axial = np.minimum(*(np.maximum(bottom - (own + heights[k]), (own + heights[k]) - top)
                         for k in (beside - 1, beside)))
    outside = np.hypot(np.maximum(radial, 0), np.maximum(axial, 0))
    return float(np.min(outside + np.minimum(np.maximum(radial, axial), 0)))


# ------------------------------------------------------------------ layouts


@st.composite
def layouts(draw):
    hobs = seeded_hobs()
    if draw(st.booleans()):
        hob = draw(st.sampled_from(hobs))
        module = hob.module
    else:
        module = draw(st.sampled_from([1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0]))
        tip = draw(st.floats(max(40.0, 12 * module), 140.0))
        hob = Hob("GEN", module, 20.0, draw(st.integers(1, 3)), round(tip, 1),
                  round(draw(st.floats(50.0, 200.0)), 1), draw(st.sampled_from("RL")), "A", "HSS", "TiN", "cylindrical")
    teeth = [draw(st.integers(10, 160)) for _ in range(2)]
    shifts = [draw(st.floats(-0.3, 0.6)) for _ in range(2)]
    tips = [round(module * (z + 2 + 2 * x), 2) for z, x in zip(teeth, shifts)]
    widths = [round(draw(st.floats(4.0, 60.0)), 1) for _ in range(2)]
    gap = round(draw(st.floats(0.0, 120.0)), 1)
    gear = Gear(9001, "duplex", module, teeth[0], 20.0, 0.0, None, widths[0], tips[0],
                round(tips[0] - 4.5 * module, 3), None, None, None, None, None, None,
                units=(GearUnit(2, teeth[1], widths[1], tips[1], None, -widths[0] - gap),))
    modes = sorted(FEED_MODES) + list(UNIT_FEED_MODES)
    choices = Choices(cuts=draw(st.sampled_from([None, 1, 2])), feed_mode=draw(st.sampled_from(modes)),
                      shift_y=draw(st.sampled_from([0.0, 0.0, 6.0, -10.0])))
    return gear, hob, choices


def units_of(gear: Gear) -> list[dict]:
    second = gear.units[0]
    return [{"tip": gear.tip_diameter, "top": 0.0, "b": gear.face_width},
            {"tip": second.tip_diameter, "top": second.z_top, "b": second.face_width}]


def check_program_cuts(gear: Gear, hob: Hob, params: dict, module_params: dict) -> float:
    """The least clearance of any cut to the other unit; asserts each pass still crosses its
    own unit's faces with the hob centre and keeps clear of the other unit."""
    reach = hob.length / 2 + abs(params["shift_y"])          # the hob shifted either way along its axis
    surface = hob_surface(hob.tip_diameter / 2, reach, swivel(hob.module, hob.starts, hob.tip_diameter))
    units, least = units_of(gear), math.inf
    for number, modules in ((1, (1, 2)), (2, (3, 4))):
        own, other = units[number - 1], units[2 - number]
        for module_number in modules:
            cut = module_params[f"cutmotion:{module_number}"]
            if not cut["cut_on"]:
                continue
            low, high = sorted((cut["z_from"], cut["z_to"]))
            assert low < own["top"] - own["b"] and high > own["top"], (
                f"unit {number}: the pass {cut['z_from']}…{cut['z_to']} does not carry the hob centre past both faces")
            found = clearance(surface, cut_centres(params["x_retract"], cut["cut_x"], cut["z_from"], cut["z_to"]),
                              other)
            assert found >= MARGIN, (f"unit {number} {cut['cut_name']}: the hob comes {found:.2f} mm near "
                                     f"the other unit (at least {MARGIN} expected)")
            least = min(least, found)
    return least


@pytest.mark.slow   # 150 random layouts, a program each
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(layouts())
def test_every_duplex_layout_gets_a_clear_program_or_a_one_line_refusal(layout):
    gear, hob, choices = layout
    try:
        job = DuplexModel().job(gear, "duplex", hob, MACHINE, CUTTING, choices)
    except EngineError as refusal:
        assert "\n" not in str(refusal) and str(refusal).startswith(f"gear {gear.id}")
        return
    check_program_cuts(gear, hob, job.params, job.module_params)


# ------------------------------------------------------------------ the issue's layout, end to end

ISSUE_HOB = "H-M4-A-R1"


def insert_duplex(conn, gear_id: int, face_width_1: float) -> None:
    """The issue's example: m4, unit 1 z74 d_a 304, unit 2 z106 d_a 433.9 at Z−75."""
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, tip_diameter, root_diameter) "
                 "VALUES (%s, 'duplex', 4, 74, %s, 304, 286)", (gear_id, face_width_1))
    conn.execute("INSERT INTO gear_unit (gear_id, unit, teeth, face_width, tip_diameter, root_diameter, z_top) "
                 "VALUES (%s, 2, 106, 20, 433.9, 415.9, -75)", (gear_id,))


def seeded_hob(hob_id: str) -> Hob:
    return next(hob for hob in seeded_hobs() if hob.id == hob_id)


def test_the_issues_layout_is_refused_in_one_line_naming_units_and_clearance(conn):
    """Unit 1 is 30 mm wide: the hob (r0 45) centred radially inside unit 2 reaches 45 mm below
    its centre, and its centre must pass Z−30, so it cannot stay clear of unit 2's face at Z−75."""
    insert_duplex(conn, 9101, 30)
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, 9101)
    message = str(refused.value)
    assert "\n" not in message
    for part in ("gear 9101", "unit 1", "unit 2", "need", "have", "smaller hob", "gap"):
        assert part in message, message
    hob = seeded_hob(ISSUE_HOB)
    assert 30 + 1 + hob.tip_diameter / 2 > 75, "the layout is one the geometry must refuse"


def program_clearances(text: str, gear_units: list[dict], hob: Hob) -> list[float]:
    """Per unit cut in the program: the least clearance of the hob to the other unit over every
    move between that unit's `; UNIT n` comment and the next."""
    program = read_program(text)
    starts = sorted((line_no, int(body.split()[1])) for line_no, body in program.comments
                    if body.strip().startswith("UNIT "))
    surface = hob_surface(hob.tip_diameter / 2, hob.length / 2, swivel(hob.module, hob.starts, hob.tip_diameter))
    found = []
    for position, (line_no, number) in enumerate(starts):
        end = starts[position + 1][0] if position + 1 < len(starts) else len(program.lines)
        moves = [m for m in program.moves if line_no < program.blocks[m.block].line_no < end and m.changed & {"X", "Z"}]
        centres = [point for m in moves for point in segment(m)]
        found.append(clearance(surface, centres, gear_units[2 - number]))
    return found


def segment(move) -> list[tuple[float, float]]:
    (x0, z0), (x1, z1) = (move.start["X"], move.start["Z"]), (move.end["X"], move.end["Z"])
    steps = max(2, int(max(abs(x1 - x0), abs(z1 - z0)) / Z_STEP) + 1)
    return list(zip(np.linspace(x0, x1, steps), np.linspace(z0, z1, steps)))


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_narrower_unit_1_gets_a_shortened_run_out_that_clears_unit_2(conn):
    """Unit 1 20 mm wide: the run-out toward unit 2 is shortened so the hob stays clear, and the
    hob centre still passes unit 1's bottom face; every move of the program keeps clear."""
    insert_duplex(conn, 9102, 20)
    program = instantiate_gear(conn, 9102, choices=Choices(feed_mode="climb"))
    hob = seeded_hob(program.lines[3].split()[2])
    units = [{"tip": 304.0, "top": 0.0, "b": 20.0}, {"tip": 433.9, "top": -75.0, "b": 20.0}]
    clearances = program_clearances("\n".join(program.lines), units, hob)
    assert len(clearances) == 2 and min(clearances) >= MARGIN, clearances
    passes = [m for m in read_program("\n".join(program.lines)).moves_in("G1") if m.changed == {"Z"}]
    unit_1_ends = [m.end["Z"] for m in passes if m.start["Z"] > -20]
    assert unit_1_ends and all(z < -20 for z in unit_1_ends), unit_1_ends
