"""No move of a turning operation enters the part: drawn tool paths and paths edited in SQL
are checked against the profile (engine.turning.gouge); threads cut below the profile by
design. The index's answer is compared with a plain even-odd test over every edge."""
from __future__ import annotations

import math
import re

import ezdxf
import pytest
from helpers.drawings import INCH, seed_drawing
from helpers.turning_jobs import refused_after
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.turning.gouge import GOUGE_TOLERANCE_MM, PartIndex, check_no_gouge
from engine.turning.moves import Move
from importers.dxf import import_dxf

# A shaft R10 from Z 0 to −60 with a collar R20 over Z −30 … −40, closed by the axis.
CORNERS = [(0.0, 0.0), (0.0, 10.0), (-30.0, 10.0), (-30.0, 20.0), (-40.0, 20.0), (-40.0, 10.0),
           (-60.0, 10.0), (-60.0, 0.0)]
EDGES = list(zip(CORNERS, CORNERS[1:] + CORNERS[:1]))


def inside_by_every_edge(z: float, r: float) -> bool:
    crossings = sum(1 for (z0, r0), (z1, r1) in EDGES
                    if min(z0, z1) <= z < max(z0, z1) and r0 + (z - z0) * (r1 - r0) / (z1 - z0) > r)
    return crossings % 2 == 1


def distance_to_outline(z: float, r: float) -> float:
    def to_edge(edge):
        (z0, r0), (z1, r1) = edge
        dz, dr = z1 - z0, r1 - r0
        t = max(0.0, min(1.0, ((z - z0) * dz + (r - r0) * dr) / (dz * dz + dr * dr)))
        return math.hypot(z - z0 - t * dz, r - r0 - t * dr)
    return min(to_edge(edge) for edge in EDGES)


@settings(max_examples=300, deadline=None)
@given(z=st.floats(-70, 10), r=st.floats(0.001, 30))
def test_the_index_finds_exactly_the_points_deep_inside_the_part(z, r):
    depth = PartIndex(EDGES).depth_inside(z, r)
    deep = inside_by_every_edge(z, r) and distance_to_outline(z, r) > GOUGE_TOLERANCE_MM
    assert (depth > 0) == deep
    if deep:
        assert depth == pytest.approx(distance_to_outline(z, r))


def test_a_move_over_the_collar_is_refused_and_one_above_it_passes():
    index = PartIndex(EDGES)
    above = [[Move("rapid", -20.0, 44.0), Move("rapid", -50.0, 44.0)]]
    check_no_gouge(above, index, "test")
    through = [[Move("rapid", -20.0, 30.0), Move("feed", -50.0, 30.0)]]   # R15 under the R20 collar
    with pytest.raises(EngineError, match=r"test: the G1 move to X30\.000 Z-50\.000 cuts") as refused:
        check_no_gouge(through, index, "test")
    depth, z = (float(v) for v in re.search(r"cuts (\S+) mm into the part at Z(\S+) X30\.000",
                                            str(refused.value)).groups())
    assert -40.0 <= z <= -30.0                                   # in the collar's span
    assert depth == pytest.approx(distance_to_outline(z, 15.0), abs=1e-3)


def test_a_finish_along_the_profile_is_not_a_gouge():
    index = PartIndex(EDGES)
    along = [[Move("rapid", 2.0, 20.0)] + [Move("feed", z, 2 * r) for z, r in CORNERS[1:-1]]]
    check_no_gouge(along, index, "finish")


def test_an_arc_dipping_into_the_part_is_refused():
    index = PartIndex(EDGES)
    # From Z −25 to Z −45 at R21 about a centre at R26: the arc dips to R16, into the collar.
    dip = [[Move("rapid", -25.0, 42.0), Move("cw", -45.0, 42.0, radius=math.hypot(10, 5), i=5.0, k=-10.0)]]
    with pytest.raises(EngineError, match="G2 move"):
        check_no_gouge(dip, index, "arc")
    over = [[Move("rapid", -25.0, 42.0), Move("ccw", -45.0, 42.0, radius=math.hypot(10, 5), i=-5.0, k=-10.0)]]
    check_no_gouge(over, index, "arc")


def test_a_slot_path_edited_into_the_part_is_refused_by_name(conn, seed_job):
    refused_after(conn, seed_job, """module_params = jsonb_set(module_params, '{cutmotion:2,paths}',
                                     '[[["line", -30, 20.32, -30, 5]]]')""",
                  r"module_params\.cutmotion:2: the G1 move to X10\.000 Z-30\.000 cuts .* mm into the part")


def test_a_drawn_rough_line_through_the_part_is_refused_at_import(conn, tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    doc = ezdxf.readfile(tmp_path / "part.dxf")
    doc.modelspace().add_line((0.1, 0.7), (-3.9, 0.7), dxfattribs={"layer": "1"})   # through the 0.75 bulge
    doc.saveas(tmp_path / "part.dxf")
    jobs = conn.execute("SELECT count(*) FROM job").fetchone()[0]
    with pytest.raises(EngineError, match=rf"cutmotion:1: the G1 move to X{2 * 0.7 * INCH:.3f} .* into the part"):
        import_dxf(conn, tmp_path / "part.dxf")
    assert conn.execute("SELECT count(*) FROM job").fetchone()[0] == jobs
