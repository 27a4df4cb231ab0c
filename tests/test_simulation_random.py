"""Random valid gears of every class, instantiated through the library on the test database:
every program is stored proved by the simulation or refused with an EngineError (one line),
never anything else. The hob envelope agrees with the hob's
points sampled densely, in plain floats (one gear's proof, issue 28) and with numpy (a batch's)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_stored_program
from engine.simulation.hobbing import envelope_arrays
from engine.simulation.hobbing.envelope import HobBody, centres, nearest_radii

GEAR_ID = 900001
INSERT_GEAR = """
INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, tip_diameter,
                  cone_angle, crowning, material, hardness, quality_grade, quantity)
VALUES (%s, %s, %s, %s, 20, %s, %s, %s, %s, %s, %s, '45', 200, 8, 10)"""
INSERT_UNIT = """INSERT INTO gear_unit (gear_id, unit, teeth, face_width, tip_diameter, root_diameter, z_top)
VALUES (%s, 2, %s, %s, %s, %s, %s)"""


@st.composite
def gears(draw):
    gear_class = draw(st.sampled_from(["spur", "helical", "taper", "crowned", "worm_wheel", "duplex"]))
    module = 3.0 if gear_class == "worm_wheel" else draw(st.sampled_from([1.5, 2.0, 2.5, 3.0, 4.0]))
    teeth = draw(st.integers(12, 90))
    helix, hand = 0.0, None
    if gear_class == "helical":
        helix, hand = draw(st.floats(5, 30)), draw(st.sampled_from(["R", "L"]))
    if gear_class == "worm_wheel":
        helix, hand = draw(st.floats(3.7, 4.4)), "R"
    width = draw(st.floats(8, 50))
    tip = module * teeth / math.cos(math.radians(helix)) + 2 * module
    cone = draw(st.sampled_from([-1, 1])) * draw(st.floats(1, 8)) if gear_class == "taper" else None
    crowning = draw(st.floats(0.005, 0.04)) if gear_class == "crowned" else None
    gear = (gear_class, module, teeth, round(helix, 3), hand, round(width, 2), round(tip, 3), cone, crowning)
    unit = None
    if gear_class == "duplex":
        teeth2 = draw(st.integers(12, 90))
        tip2 = module * (teeth2 + 2)
        unit = (teeth2, round(draw(st.floats(8, 40)), 2), tip2, tip2 - 4.5 * module,
                round(-width - draw(st.floats(5, 80)), 2))
    choices = Choices(cuts=draw(st.sampled_from([None, 1, 2])),
                      feed_mode=draw(st.sampled_from(["climb", "conventional", "conventional-climb"])),
                      tailstock=draw(st.booleans()), worm_feed=draw(st.sampled_from(["radial", "tangential"])))
    return gear, unit, choices


def _insert(conn, gear, unit) -> None:
    conn.execute(INSERT_GEAR, (GEAR_ID, *gear))
    if unit:
        conn.execute(INSERT_UNIT, (GEAR_ID, *unit))


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=gears())
def test_random_gears_are_proved_or_refused_in_one_line(conn, case):
    gear_row, unit, choices = case
    with conn.transaction(force_rollback=True):
        _insert(conn, gear_row, unit)
        try:
            program = instantiate_gear(conn, GEAR_ID, choices=choices)
        except EngineError as error:
            assert "\n" not in str(error)
        else:
            assert not simulate_stored_program(conn, program.program_id).refused


def hob_points(body: HobBody, swivel: float, centre, count: int = 200) -> np.ndarray:
    """Points of the tip cylinder and both end faces, sampled on a grid, DIN coordinates."""
    a = math.radians(swivel)
    axis, e1, e2 = (np.array([0, math.cos(a), math.sin(a)]), np.array([1.0, 0, 0]),
                    np.array([0, -math.sin(a), math.cos(a)]))
    t, phi = np.meshgrid(np.linspace(-body.half_length, body.half_length, count), np.linspace(0, 2 * math.pi, count))
    ring = np.cos(phi)[..., None] * -e1 + np.sin(phi)[..., None] * e2
    surface = [t[..., None] * axis + body.radius * ring]
    share = np.linspace(0, 1, count // 4)[None, :, None]
    for end in (-body.half_length, body.half_length):
        surface.append(end * axis + body.radius * share * ring[:, : count // 4])
    return np.concatenate([p.reshape(-1, 3) for p in surface]) + np.asarray(centre)


def in_plain_floats(body: HobBody, swivel: float, cx, cy, cz, heights) -> np.ndarray:
    """engine.simulation.hobbing.envelope.nearest_radii pose by pose, shaped as the numpy version's."""
    rows = np.broadcast_to(heights, (len(cx), heights.shape[1])).tolist()
    return np.array([nearest_radii(body, swivel, float(x), float(y), float(z), row)
                     for x, y, z, row in zip(cx[:, 0], cy[:, 0], cz[:, 0], rows)])


ENVELOPES = {"plain floats": in_plain_floats, "numpy": envelope_arrays.nearest_radius}


@pytest.mark.slow
@pytest.mark.parametrize("envelope", ENVELOPES)
@settings(max_examples=40, deadline=None)
@given(radius=st.floats(20, 50), length=st.floats(60, 160), swivel=st.floats(-35, 35), x=st.floats(25, 120),
       y=st.floats(-40, 40))
def test_the_envelope_is_the_nearest_point_of_the_hob_at_each_height(envelope, radius, length, swivel, x, y):
    nearest_radius = ENVELOPES[envelope]
    body = HobBody(radius, length / 2)
    x = max(x, radius + 1.0)
    cx, cy, cz = (np.array([value]) for value in centres(x, y, 0.0, swivel))
    points = hob_points(body, swivel, (cx[0], cy[0], cz[0]))
    distance = np.hypot(points[:, 0], points[:, 1])
    at_heights = nearest_radius(body, swivel, cx[:, None], cy[:, None], cz[:, None], points[None, :, 2])[0]
    assert (at_heights <= distance + 1e-6).all()          # never farther than a point of the hob at that height
    extent = body.extent(swivel)
    grid = np.linspace(-extent, extent, 2001)[None, :]
    nearest = nearest_radius(body, swivel, cx[:, None], cy[:, None], cz[:, None], grid).min()
    step_along, step_round = length / 199, 2 * math.pi / 199          # the sampling grid of hob_points
    resolution = step_along / 2 + radius * step_round ** 2 / 8 + 0.01
    assert nearest >= distance.min() - resolution          # and as near as the hob comes, to the sampling


@settings(max_examples=60, deadline=None)
@given(radius=st.floats(20, 50), length=st.floats(60, 160), swivel=st.floats(-35, 35), x=st.floats(0, 120),
       y=st.floats(-40, 40), z=st.floats(-60, 60))
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_envelope_in_plain_floats_and_with_numpy_agree(radius, length, swivel, x, y, z):
    """A process follows its first sections in plain floats and the rest with numpy
    (engine.simulation.hobbing.contact.MATH_SECTIONS): the two give one distance, to a micrometre."""
    body = HobBody(radius, length / 2)
    cx, cy, cz = (np.array([[value]]) for value in centres(x, y, z, swivel))
    heights = np.linspace(z - 100, z + 100, 401)[None, :]
    plain, arrays = in_plain_floats(body, swivel, cx, cy, cz, heights), envelope_arrays.nearest_radius(
        body, swivel, cx, cy, cz, heights)
    assert (np.isinf(plain) == np.isinf(arrays)).all()
    finite = np.isfinite(plain)
    assert np.abs(plain[finite] - arrays[finite]).max(initial=0.0) < 0.001   # mm: a micrometre
