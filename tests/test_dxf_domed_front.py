"""Profiles that start on the axis (issue 27): a ball end, a cone point. The finish pass must
come in from outside the part — never from below the axis, which is the part's other side
and beyond the lathe's X travel — and the program must pass the verifier, the gouge, finish
and material checks and the turning simulation (`engine instantiate --job` runs them all).

The parts are drawn here with ezdxf in mm; the expected approach is computed from the drawn
geometry: the point on the axis, clearance in front of it."""
from __future__ import annotations

import math
import re

import ezdxf
import pytest
from helpers.outcomes import made

from engine.drawings.geometry import Arc, Line
from engine.turning.toolpaths import finish_passes

BALL_RADIUS, SHAFT_END = 10.0, -40.0
CLEARANCE = 2.0


def ball_end(path):
    """A shaft Ø20 whose front (Z 0) is a hemisphere R10 centred at Z -10 on the axis."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_arc((-BALL_RADIUS, 0), BALL_RADIUS, 0, 90)
    msp.add_line((-BALL_RADIUS, BALL_RADIUS), (SHAFT_END, BALL_RADIUS))
    msp.add_line((SHAFT_END, BALL_RADIUS), (SHAFT_END, 0))
    doc.saveas(path)
    return path


def cone_point(path, point_angle_deg):
    """A shaft Ø20 with a cone point at Z 0 of the given included angle."""
    length = BALL_RADIUS / math.tan(math.radians(point_angle_deg / 2))
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(0, 0), (-length, BALL_RADIUS), (SHAFT_END, BALL_RADIUS), (SHAFT_END, 0)])
    doc.saveas(path)
    return path


@pytest.mark.parametrize("path", [
    [Arc((0.0, 0.0), (-10.0, 10.0), (-10.0, 0.0), True)],                 # dome: starts radial
    [Line((0.0, 0.0), (-2.0, 10.0))],                                      # blunt cone point (157°)
    [Line((0.0, 0.0), (-10.0, 10.0))],                                     # 90° point
])
def test_a_finish_pass_starting_on_the_axis_comes_in_along_it_from_the_front(path):
    first, second = finish_passes(path, CLEARANCE)[0][:2]
    assert first.kind == "rapid" and first.x >= 0.0 and first.z > 0.0   # in the air in front of the point
    assert first.x == pytest.approx(0.0, abs=1e-9) or first.x > 0
    assert (second.kind, second.z, second.x) == ("feed", 0.0, 0.0)


def words(line: str) -> dict[str, float]:
    return {letter: float(value) for letter, value in re.findall(r"\b([XZ])(-?\d*\.?\d+)", line)}


@pytest.mark.parametrize(("draw", "machine"), [(ball_end, "lathe-iso"), (ball_end, "lathe-840d"),
                                               (lambda p: cone_point(p, 150), "lathe-iso")],
                         ids=["ball-end-iso", "ball-end-840d", "point-150-iso"])
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_parts_with_a_dome_or_point_in_front_become_jobs_whose_programs_pass(run, tmp_path, draw, machine):
    path = draw(tmp_path / "part.dxf")
    job = made(run("import-dxf", path, "--rough-depth", "1", "--machine", machine, "--program-name", "DOMED", "--json"))
    program = made(run("instantiate", "--job", job["job_id"], "--json"))   # verifier, gouge, finish, material
    assert not program["unverified"]
    lines = run("programs", "show", program["program_id"]).stdout.splitlines()
    moves = [words(line) for line in lines if words(line)]
    assert min(move["X"] for move in moves if "X" in move) >= 0.0   # never below the axis
    assert {"X": 0.0, "Z": 0.0} in moves   # the point on the axis is cut
    simulated = run("simulate", "--program", program["program_id"])
    assert simulated.exit_code == 0, simulated.output
