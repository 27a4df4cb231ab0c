"""Tool paths of turning jobs (design notes §8), no database.

Expected values come from the geometry, computed here: the drawn segments, the seed
drawing's numbers (inches, as seed_drawing writes them), exact distances to lines and
arcs (no flattening), and the G2/G3 sense of a lathe seen with Z to the right and the
radius up — never from the tool-path code's own output."""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from helpers.drawings import seed_drawing
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.drawings.drawing import read_drawing
from engine.drawings.geometry import Arc, Line
from engine.errors import EngineError
from engine.turning.moves import Move
from engine.turning.plot import plot_job
from engine.turning.region import CHORD_TOLERANCE_MM
from engine.turning.toolpaths import (
    alternate,
    distance_to_region,
    drawn_rough_passes,
    finish_passes,
    profile_rough_passes,
    slot_passes,
    thread_passes,
)

INCH = 25.4
CLEARANCE = 1.0
FEED_SAMPLE_MM = 0.05
# The planner keeps 1 µm (its chord tolerance) more than the allowance from flattened
# arcs; points this much beyond allowance + depth must be reached, with room to spare.
COVERAGE_MARGIN_MM = 0.01
COVERAGE_GRID_MM = 0.4


# --- exact geometry, independent of engine.turning ---------------------------------

def arc_sweep(arc: Arc) -> float:
    a0 = math.atan2(arc.start[1] - arc.centre[1], arc.start[0] - arc.centre[0])
    a1 = math.atan2(arc.end[1] - arc.centre[1], arc.end[0] - arc.centre[0])
    return ((a1 - a0) if arc.ccw else (a0 - a1)) % (2 * math.pi)


def on_arc(arc: Arc, angles: np.ndarray) -> np.ndarray:
    """Whether directions (angles about the centre) lie within the arc's sweep."""
    a0 = math.atan2(arc.start[1] - arc.centre[1], arc.start[0] - arc.centre[0])
    turned = (angles - a0) % (2 * math.pi) if arc.ccw else (a0 - angles) % (2 * math.pi)
    return turned <= arc_sweep(arc) + 1e-12


def segment_distances(points: np.ndarray, segment) -> np.ndarray:
    """Exact distance from each (z, r) point to a line or an arc."""
    start, end = np.array(segment.start), np.array(segment.end)
    if isinstance(segment, Line):
        direction = end - start
        t = np.clip(((points - start) @ direction) / max(direction @ direction, 1e-300), 0.0, 1.0)
        return np.linalg.norm(points - (start + t[:, None] * direction), axis=1)
    centre = np.array(segment.centre)
    offset = points - centre
    radius = math.dist(segment.start, segment.centre)
    to_circle = np.abs(np.linalg.norm(offset, axis=1) - radius)
    to_ends = np.minimum(np.linalg.norm(points - start, axis=1), np.linalg.norm(points - end, axis=1))
    return np.where(on_arc(segment, np.arctan2(offset[:, 1], offset[:, 0])), to_circle, to_ends)


def top_radius(z: np.ndarray, segments) -> np.ndarray:
    """The profile's radius above each z (the largest boundary point there), exactly."""
    top = np.full(z.shape, -np.inf)
    for segment in segments:
        (z0, r0), (z1, r1) = segment.start, segment.end
        if isinstance(segment, Line):
            if abs(z1 - z0) < 1e-12:
                continue
            within = (z >= min(z0, z1)) & (z <= max(z0, z1))
            radius = r0 + (z - z0) * (r1 - r0) / (z1 - z0)
            top = np.where(within, np.maximum(top, radius), top)
            continue
        (cz, cr), big = segment.centre, math.dist(segment.start, segment.centre)
        rise = np.sqrt(np.clip(big ** 2 - (z - cz) ** 2, 0.0, None))
        inside_circle = np.abs(z - cz) <= big
        for radius in (cr + rise, cr - rise):
            hit = inside_circle & on_arc(segment, np.arctan2(radius - cr, z - cz))
            top = np.where(hit, np.maximum(top, radius), top)
    return top


def exact_distance(points: np.ndarray, profile, z_front: float, z_back: float) -> np.ndarray:
    """Distance to the region under a half-profile over [z_back, z_front], 0 inside."""
    outline = profile + closing(profile)
    nearest = np.min([segment_distances(points, s) for s in outline], axis=0)
    z, r = points[:, 0], points[:, 1]
    inside = (z > z_back) & (z < z_front) & (r >= 0) & (r < top_radius(z, profile))
    return np.where(inside, 0.0, nearest)


def closing(profile) -> list[Line]:
    (z_start, r_start), (z_end, r_end) = profile[0].start, profile[-1].end
    corners = [(z_end, r_end), (z_end, 0.0), (z_start, 0.0), (z_start, r_start)]
    return [Line(a, b) for a, b in zip(corners, corners[1:]) if math.dist(a, b) > 0]


def polyline(passes, kinds=("feed",)) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """(start, end) in (z, r) of the moves of the given kinds, each from the move before."""
    found, here = [], None
    for move in (m for one in passes for m in one):
        end = (move.z, move.x / 2.0)
        if here is not None and move.kind in kinds:
            found.append((here, end))
        here = end
    return found


def sampled(lines) -> np.ndarray:
    points = []
    for start, end in lines:
        count = max(1, math.ceil(math.dist(start, end) / FEED_SAMPLE_MM))
        points += [(start[0] + (end[0] - start[0]) * n / count, start[1] + (end[1] - start[1]) * n / count)
                   for n in range(count + 1)]
    return np.array(points)


# --- finishing ------------------------------------------------------------------------

def finish_profile():
    """Front face, a dome (over the top: G3), a groove (under: G2), a chamfer, a step."""
    return [Line((0.0, 4.0), (0.0, 10.0)), Line((0.0, 10.0), (-5.0, 10.0)),
            Arc((-5.0, 10.0), (-15.0, 10.0), (-10.0, 10.0), ccw=True),
            Arc((-15.0, 10.0), (-25.0, 10.0), (-20.0, 10.0), ccw=False),
            Line((-25.0, 10.0), (-27.0, 12.0)), Line((-27.0, 12.0), (-40.0, 12.0))]


def midpoint_of(start, move: Move) -> tuple[float, float]:
    """Rotate the start half way about the centre the way G2 (clockwise) / G3 go."""
    centre = (start[0] + move.k, start[1] + move.i)
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(move.x / 2 - centre[1], move.z - centre[0])
    turn = (a1 - a0) % (2 * math.pi) if move.kind == "ccw" else -((a0 - a1) % (2 * math.pi))
    return (centre[0] + move.radius * math.cos(a0 + turn / 2), centre[1] + move.radius * math.sin(a0 + turn / 2))


def test_finish_pass_reproduces_the_profile_and_arc_directions():
    profile = finish_profile()
    (moves,) = finish_passes(profile, CLEARANCE)
    approach, infeed, *cutting = moves
    # The front face runs outwards (+r): approached from in front of it (+Z) and below.
    assert (approach.kind, approach.z, approach.x) == ("rapid", CLEARANCE, pytest.approx(2 * (4.0 - CLEARANCE)))
    assert (infeed.kind, infeed.z, infeed.x) == ("feed", 0.0, pytest.approx(8.0))
    assert [m.kind for m in cutting] == ["feed", "feed", "ccw", "cw", "feed", "feed"]
    for move, segment in zip(cutting, profile):
        assert move.z == pytest.approx(segment.end[0], abs=1e-9)
        assert move.x == pytest.approx(2 * segment.end[1], abs=1e-9)
    dome, groove = cutting[2], cutting[3]
    for move, segment, middle in ((dome, profile[2], (-10.0, 15.0)), (groove, profile[3], (-20.0, 5.0))):
        assert (segment.start[0] + move.k, segment.start[1] + move.i) == pytest.approx(segment.centre, abs=1e-9)
        assert move.radius == pytest.approx(5.0)
        assert midpoint_of(segment.start, move) == pytest.approx(middle, abs=1e-9)


# --- the seed drawing -----------------------------------------------------------------

@pytest.fixture(scope="module")
def seed_operations(tmp_path_factory):
    path = tmp_path_factory.mktemp("seed") / "part.dxf"
    seed_drawing(path)
    return {op.kind: op for op in read_drawing(path).operations}


def test_seed_rough_passes_follow_the_seed_motions(seed_operations):
    passes = drawn_rough_passes(seed_operations["ROUGH"].paths, CLEARANCE)
    start_z, end_z = 0.1 * INCH, -3.9 * INCH
    assert len(passes) == 3
    for moves, radius in zip(passes, (0.9 * INCH, 0.85 * INCH, 0.8 * INCH)):
        assert [m.kind for m in moves] == ["rapid", "feed", "feed"]
        expected = [(start_z, radius + CLEARANCE),   # 5: X re-approach
                    (start_z, radius),               # 1: G01 X infeed
                    (end_z, radius)]                 # 2: G01 Z along the drawn line
        assert [(m.z, m.x / 2) for m in moves] == [pytest.approx(p) for p in expected]
    # 3, 4: the retract (X) and the Z return run at the travel radius, added by standalone().


def test_seed_slot_plunges_one_per_drawn_line(seed_operations):
    passes = slot_passes(seed_operations["SLOT"].paths, CLEARANCE)
    outer, inner = 0.8 * INCH + CLEARANCE, 0.1 * INCH
    expected = [[("rapid", z, outer), ("feed", z, inner), ("rapid", z, outer)]
                for z in (-2.3 * INCH, -2.7 * INCH)]
    assert [[(m.kind, m.z, m.x / 2) for m in moves] for moves in passes] == [
        [(kind, pytest.approx(z), pytest.approx(r)) for kind, z, r in plunge] for plunge in expected]


def test_seed_thread_passes_compound_infeed(seed_operations):
    thread = seed_operations["THREAD"]
    d, angle, pitch = (thread.codes[k] for k in ("depth_per_pass", "infeed_angle", "thread_pitch"))
    passes = thread_passes(thread.paths, d, angle, pitch, CLEARANCE)
    crest, root, start_z, end_z = 0.5 * INCH, 0.45 * INCH, -0.2 * INCH, -0.9 * INCH
    depth = crest - root
    assert len(passes) == math.ceil(depth / d) == 4
    final_start = passes[-1][0].z
    # The run-in before the drawn start (towards +Z, the side the cut comes from) is whole
    # pitches, so the last pass lies on the drawn thread.
    run_in = (final_start - start_z) / pitch
    assert run_in >= CLEARANCE / pitch - 1e-9 and run_in == pytest.approx(round(run_in), abs=1e-9)
    shifts = []
    for number, moves in enumerate(passes, start=1):
        pass_depth = min(number * d, depth)
        assert [m.kind for m in moves] == ["rapid", "rapid", "thread"]
        cut = moves[2]
        assert (cut.z, cut.x / 2, cut.pitch) == (pytest.approx(end_z), pytest.approx(crest - pass_depth), pitch)
        assert moves[1].z == moves[0].z and moves[0].x / 2 == pytest.approx(crest + CLEARANCE)
        # Compound infeed along the flank: (H − d)·tan A towards the start side.
        shifts.append(moves[0].z - final_start)
        assert shifts[-1] == pytest.approx((depth - pass_depth) * math.tan(math.radians(angle)))
    assert shifts == sorted(shifts, reverse=True) and shifts[-1] == 0
    assert passes[-1][2].x / 2 == pytest.approx(root)


def axial(z0, z1, r):
    return [Line((z0, r), (z1, r))]


@pytest.mark.parametrize("depth, per_pass, count", [(1.2, 0.4, 3), (1.1, 0.1, 11), (0.3, 0.1, 3), (1.0, 0.3, 4)])
def test_thread_pass_count_ignores_float_noise(depth, per_pass, count):
    passes = thread_passes([axial(0, -10, 6.0), axial(0, -10, 6.0 - depth)], per_pass, 0, 1.0, CLEARANCE)
    assert len(passes) == count
    assert passes[-1][2].x / 2 == pytest.approx(6.0 - depth)


@pytest.mark.parametrize("paths, per_pass, words", [
    ([axial(0, -10, 6.0)], 0.4, "two axial lines"),
    ([axial(0, -10, 6.0), [Line((0, 6), (-10, 5))]], 0.4, "two axial lines"),
    ([axial(0, -10, 6.0), axial(0, -10, 6.0)], 0.4, "depth is 0"),
    ([axial(0, -10, 6.0), axial(0, -10, 5.0)], 0.0, "@D"),
])
def test_thread_refusals_name_the_problem(paths, per_pass, words):
    with pytest.raises(EngineError, match=words) as refused:
        thread_passes(paths, per_pass, 30, 1.5, CLEARANCE)
    assert "\n" not in str(refused.value)


def test_drawn_rough_path_followed_segment_by_segment():
    path = [Line((2.0, 8.0), (-5.0, 8.0)), Arc((-5.0, 8.0), (-9.0, 8.0), (-7.0, 8.0), ccw=True)]
    (moves,) = drawn_rough_passes([path], CLEARANCE)
    assert [m.kind for m in moves] == ["rapid", "feed", "feed", "ccw"]
    assert (moves[-1].z, moves[-1].x / 2) == pytest.approx((-9.0, 8.0))


# --- roughing from the profile -----------------------------------------------------------

@st.composite
def stepped_profiles(draw):
    """A shaft from Z 0 backwards: flats joined by steps — a plain shoulder or a chamfer
    (up or down, so pockets occur), a concave fillet (G2) or a round (G3) going up — and
    now and then a semicircular groove (G2) or dome (G3) in a flat."""
    radius, z, segments = draw(st.floats(3.0, 8.0)), 0.0, []
    for _ in range(draw(st.integers(1, 3))):
        flat = draw(st.floats(3.0, 15.0))
        segments.append(Line((z, radius), (z - flat, radius)))
        z -= flat
        kind = draw(st.sampled_from(["shoulder", "chamfer", "fillet", "round", "groove", "dome"]))
        rise = draw(st.floats(-6.0, 8.0).filter(lambda value: abs(value) >= 1.0))
        if kind in ("fillet", "round"):
            rise = abs(rise)
        rise = max(rise, 1.0 - radius)
        size = draw(st.floats(0.2, 0.8)) * min(abs(rise), 2.5, radius - 0.5)
        segments += step(z, radius, radius + rise, kind, size)
        z, radius = segments[-1].end
    flat = draw(st.floats(3.0, 15.0))
    segments.append(Line((z, radius), (z - flat, radius)))
    return segments


def step(z, low, high, kind, size):
    if kind == "shoulder":
        return [Line((z, low), (z, high))]
    if kind == "chamfer":
        return [Line((z, low), (z - size, high))]
    if kind in ("groove", "dome"):   # under the flat (clockwise) or over it, at the same radius
        return [Arc((z, low), (z - 2 * size, low), (z - size, low), ccw=kind == "dome")]
    if kind == "fillet":   # the inner corner rounded: from below the centre to its left
        return [Arc((z, low), (z - size, low + size), (z, low + size), ccw=False),
                Line((z - size, low + size), (z - size, high))]
    # the outer corner rounded: from the centre's right to above it
    return [Line((z, low), (z, high - size)),
            Arc((z, high - size), (z - size, high), (z - size, high - size), ccw=True)]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(profile=stepped_profiles(), extra=st.floats(0.5, 6.0), per_pass=st.floats(0.5, 3.0),
       allowance=st.floats(0.0, 1.0), front_stock=st.sampled_from([0.0, 0.5, 2.0]))
def test_profile_roughing_keeps_the_allowance_and_removes_the_material(profile, extra, per_pass,
                                                                       allowance, front_stock):
    z_back = profile[-1].end[0]
    top = float(top_radius(np.linspace(z_back, 0.0, 20001), profile).max())   # domes rise above their ends
    stock, z_front = top + extra, front_stock
    outline = profile + closing(profile)
    passes = profile_rough_passes(outline, stock, per_pass, allowance, z_front, z_back, CLEARANCE)
    cuts, travel = polyline(passes), polyline(passes, kinds=("rapid",))
    if cuts:
        assert exact_distance(sampled(cuts), profile, 0.0, z_back).min() >= allowance - 1e-6
        assert exact_distance(sampled(travel), profile, 0.0, z_back).min() >= allowance - 1e-6
    grid = np.array([(z, r) for z in np.arange(z_back, z_front + 1e-9, COVERAGE_GRID_MM)
                     for r in np.arange(0.0, stock + 1e-9, COVERAGE_GRID_MM)] + [(z_back, stock), (z_front, stock)])
    material = grid[exact_distance(grid, profile, 0.0, z_back) >= allowance + per_pass + COVERAGE_MARGIN_MM]
    if len(material):   # less than allowance + depth above the part needs no rough pass
        assert cuts
        reach = np.min([segment_distances(material, Line(a, b)) for a, b in cuts], axis=0)
        # within the 1 µm the roughing keeps off flattened arcs and flats (a level 10 nm above
        # a flat is moved onto the flat + 1 µm: the layer above it is 10 nm thicker than D)
        assert reach.max() <= per_pass + CHORD_TOLERANCE_MM


def test_profile_roughing_levels_from_the_outside_in():
    profile = [Line((0.0, 5.0), (-10.0, 5.0)), Line((-10.0, 5.0), (-10.0, 9.0)), Line((-10.0, 9.0), (-30.0, 9.0))]
    passes = profile_rough_passes(profile + closing(profile), 12.0, 2.0, 0.5, 0.0, -30.0, CLEARANCE)
    levels = [moves[[m.kind for m in moves].index("feed")].x / 2 for moves in passes]
    # Levels 10, 8, 6 (12 − k·2; 4 would be inside 5 + 0.5) and one on each flat grown by
    # the allowance (+ 1 µm chords), so nothing beyond the allowance is left on them.
    assert levels == pytest.approx([10.0, 9.501, 8.0, 6.0, 5.501], abs=1e-5)
    last = polyline(passes[-1:])[-1]
    assert last[1][0] == pytest.approx(-10.0 + 0.5 + 0.001, abs=1e-6)   # the shoulder + allowance (+ 1 µm chords)
    assert last[0][0] == pytest.approx(CLEARANCE)   # starts in the air in front of the blank


@pytest.mark.parametrize("change, words", [
    ({"depth_per_pass": 0.0}, "--rough-depth"), ({"allowance": -0.1}, "--allowance"),
    ({"stock_radius": 5.0}, "--stock-diameter"), ({"clearance": 0.0}, "params.clearance"),
    ({"stock_radius": 8.0}, "the part does not fit in the blank; give --stock-diameter"),
])
def test_profile_roughing_refuses_bad_numbers(change, words):
    profile = [Line((0.0, 5.0), (-10.0, 5.0)), Line((-10.0, 5.0), (-10.0, 9.0)), Line((-10.0, 9.0), (-30.0, 9.0))]
    numbers = dict(stock_radius=12.0, depth_per_pass=2.0, allowance=0.5, z_front=0.0, z_back=-30.0,
                   clearance=CLEARANCE) | change
    with pytest.raises(EngineError, match=words):
        profile_rough_passes(profile + closing(profile), **numbers)


@settings(max_examples=20, deadline=None)
@given(profile=stepped_profiles(), z=st.floats(-60.0, 5.0), r=st.floats(0.0, 30.0))
def test_distance_to_region_matches_exact_geometry(profile, z, r):
    exact = exact_distance(np.array([(z, r)]), profile, 0.0, profile[-1].end[0])[0]
    assert distance_to_region((z, r), profile + closing(profile)) == pytest.approx(exact, abs=0.0011)


# --- crossing work steps --------------------------------------------------------------------

def test_alternate_interleaves_then_appends_the_rest():
    first = [[Move("feed", float(n), 1.0)] for n in range(3)]
    second = [[Move("feed", float(n), 2.0)] for n in range(5)]
    crossed = alternate(first, second)
    assert crossed == [first[0], second[0], first[1], second[1], first[2], second[2], second[3], second[4]]
    assert alternate([], second) == second and alternate(first, []) == first


# --- plotting --------------------------------------------------------------------------------

def plot_inputs():
    profile = finish_profile()
    outline = profile + closing(profile)
    roughing = profile_rough_passes(outline, 15.0, 2.0, 0.5, 1.0, -40.0, CLEARANCE)
    return outline, (1.0, -40.0, 15.0), [("rough", 1, roughing), ("finish", 2, finish_passes(profile, CLEARANCE))]


@pytest.mark.parametrize("name, magic", [("part.png", b"\x89PNG"), ("part.svg", b"<svg")])
def test_plot_writes_png_and_svg(tmp_path, name, magic):
    plot_job(tmp_path / name, *plot_inputs())
    written = (tmp_path / name).read_bytes()
    assert written and magic in written[:2000]
    assert os.listdir(tmp_path) == [name]


def test_plot_refuses_other_formats_and_leaves_nothing(tmp_path):
    with pytest.raises(EngineError, match=r"FILE\.png or FILE\.svg"):
        plot_job(tmp_path / "part.jpg", *plot_inputs())
    assert os.listdir(tmp_path) == []


def test_plot_failure_leaves_no_half_written_file(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    def broken(self, filename, **_):
        Path(filename).write_bytes(b"\x89PNG half")
        raise OSError("disk full")

    monkeypatch.setattr(Figure, "savefig", broken)
    with pytest.raises(EngineError, match=r"cannot write the picture .*part\.png.*: disk full"):
        plot_job(tmp_path / "part.png", *plot_inputs())
    assert os.listdir(tmp_path) == []


def shaft_with_collar_surroundings():
    """Shaft R10 from Z 0 to Z −70 with a collar R20 at Z −30 … −40, closed by the axis."""
    from engine.turning.region import Surroundings, flattened_outline

    corners = [(0, 0), (0, 10), (-30, 10), (-30, 20), (-40, 20), (-40, 10), (-70, 10), (-70, 0)]
    outline = [Line(a, b) for a, b in zip(corners, corners[1:] + corners[:1])]
    return Surroundings(tuple(flattened_outline(outline)), None, CLEARANCE)


def test_a_thread_whose_run_in_would_cut_the_part_is_refused():
    around = shaft_with_collar_surroundings()
    # Drawn from −62 towards −45 on the R10 shaft: before its start the shaft goes on to −70
    # (the chuck side), so no run-in in the air exists.
    towards_the_face = [axial(-62, -45, 10.0), axial(-62, -45, 9.0)]
    with pytest.raises(EngineError, match=r"THREAD starting at Z -62: the part continues before it"):
        thread_passes(towards_the_face, 0.3, 30, 1.5, CLEARANCE, around)
    # Drawn from −20 towards −28 at the free end: the run-in goes through the shaft (radius
    # 10 = the crest) to the front face, in the air beyond it by at least the clearance.
    at_the_free_end = [axial(-20, -28, 10.0), axial(-20, -28, 9.0)]
    passes = thread_passes(at_the_free_end, 0.3, 0, 1.5, CLEARANCE, around)
    starts = {one[0].z for one in passes}
    assert len(starts) == 1 and starts.pop() >= 0 + CLEARANCE
    # A collar larger than the crest before the start would be cut too.
    behind_the_collar = [axial(-45, -60, 10.0), axial(-45, -60, 9.0)]
    with pytest.raises(EngineError, match="run-in would cut it"):
        thread_passes(behind_the_collar, 0.3, 0, 1.5, CLEARANCE, around)


def test_a_facing_cut_leaves_its_face_along_z_before_any_x_retract():
    face = [[Line((0.0, 30.0), (0.0, 0.0))]]
    moves = drawn_rough_passes(face, CLEARANCE)[0]
    last_cut = max(i for i, move in enumerate(moves) if move.kind == "feed")
    assert (moves[last_cut].z, moves[last_cut].x) == (0.0, 0.0)
    leave = moves[last_cut + 1]
    assert leave.kind == "rapid" and leave.x == 0.0 and leave.z == pytest.approx(CLEARANCE)
