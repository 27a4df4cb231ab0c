"""The picture of a turning job (`engine plot --job ID`) as a user reads it against the program:
X as a diameter, one colour per operation, rapids told from feed moves, a title naming the job,
the tool-change point marked, limits around the work.

What was drawn is read from the matplotlib Figure (axis labels, Line2D colours and data), not
from pixels. Expected numbers come from the instantiated program's own words (X diameters, Z)
and from the drawings, never from the plotting code."""
from __future__ import annotations

import json
import math

import pytest
from helpers.drawings import DXF, INCH, seed_drawing
from helpers.drawn_parts import two_rough_layers
from helpers.lathe_programs import distance_to_drawn, drawn_polylines, operation_lines, words

from engine.programs.remake import instantiate_job
from engine.turning.job_params import ProfileOptions
from engine.turning.job_plot import turning_job_figure
from importers.dxf import import_dxf

HEMISPHERE = "emco_lathe_testg02hemisphere_R14.dxf"
PRINTED_MM = 0.0005   # the program states positions to 0.001 mm, rounded
FEED_CODES = (1, 2, 3, 32, 33)
ARC_TOLERANCE_MM = 0.002   # the arcs' ends are printed to 0.001 mm; their drawn points sit on the arc


def job_and_program(conn, path, program_name=None, alternate=None, **options) -> tuple[int, list[str]]:
    report = import_dxf(conn, path, "lathe-iso", ProfileOptions(**options), alternate, program_name)
    return report.job_id, instantiate_job(conn, report.job_id).lines


def hemisphere_job(conn) -> tuple[int, list[str]]:
    """The real Emco drawing, roughed and finished with one tool (the profile-only default)."""
    return job_and_program(conn, DXF / HEMISPHERE, "EMCO_G02", rough_depth=1.0)


def points(blocks: list[str], codes) -> list[tuple[float, float]]:
    """(Z, X) where each block of the given G codes ends, X as written (a diameter)."""
    found, here = [], {}
    for block in blocks:
        said = words(block)
        here.update({letter: said[letter] for letter in ("X", "Z") if letter in said})
        if said.get("G") in codes and ("X" in said or "Z" in said):
            found.append((here["Z"], here["X"]))
    return found


def drawn_operations(figure) -> dict[str, list]:
    """Every operation's lines by its legend label ('OP 2 FINISH T1'): its feed line (labelled)
    and its rapid line (labelled '_OP 2 FINISH T1 rapid', left out of the legend)."""
    found: dict[str, list] = {}
    for line in figure.axes[0].lines:
        name = line.get_label().lstrip("_").removesuffix(" rapid")
        if name.startswith("OP "):
            found.setdefault(name, []).append(line)
    return found


def vertices(line) -> list[tuple[float, float]]:
    return [tuple(point) for point in line.get_xydata() if not math.isnan(point[0])]


def has_vertex(line, point) -> bool:
    return any(math.dist(vertex, point) <= 2 * PRINTED_MM for vertex in vertices(line))


def feed_and_rapid(lines) -> tuple:
    feed = next(line for line in lines if not line.get_label().startswith("_"))
    rapid = next(line for line in lines if line.get_label().endswith(" rapid"))
    return feed, rapid


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_vertical_axis_is_the_diameter_the_program_writes(conn):
    job_id, program = hemisphere_job(conn)
    figure = turning_job_figure(conn, job_id)
    assert "diameter" in figure.axes[0].get_ylabel()
    feed, _ = feed_and_rapid(drawn_operations(figure)["OP 2 FINISH T1"])
    finish_blocks = operation_lines(program, 2)
    finish = points(finish_blocks, FEED_CODES)
    assert any(block.startswith("G02 ") for block in finish_blocks)   # the hemisphere: arcs drawn too
    for point in finish:
        assert has_vertex(feed, point), point
    # The bottom of the hemisphere: X2 in the program (radius 1 in the drawing) sits at 2 on the axis.
    lowest = min(x for _, x in vertices(feed))
    assert lowest == pytest.approx(min(x for _, x in finish), abs=PRINTED_MM)
    assert lowest == pytest.approx(2.0, abs=PRINTED_MM)
    # Between its ends (Z −10 … −20) the arc is drawn on the drawn hemisphere, not bulging away.
    on_arc = [(z, x / 2.0) for z, x in vertices(feed) if -20.0 < z < -10.0]
    drawn = drawn_polylines(DXF / HEMISPHERE)
    assert len(on_arc) > 10 and all(distance_to_drawn(point, drawn) <= ARC_TOLERANCE_MM for point in on_arc)


def test_every_operation_has_its_own_colour_even_with_one_tool(conn):
    job_id, program = hemisphere_job(conn)
    assert [block for block in program if block.startswith("T")] == ["T0101", "T0101"]   # rough, finish: T1
    drawn = drawn_operations(turning_job_figure(conn, job_id))
    assert sorted(drawn) == ["OP 1 ROUGH T1", "OP 2 FINISH T1"]
    colours = {name: {line.get_color() for line in lines} for name, lines in drawn.items()}
    assert all(len(found) == 1 for found in colours.values()), colours   # feed and rapid alike
    assert colours["OP 1 ROUGH T1"] != colours["OP 2 FINISH T1"]


def test_rapids_are_dashed_feeds_solid_and_the_legend_says_so(conn):
    job_id, program = hemisphere_job(conn)
    figure = turning_job_figure(conn, job_id)
    for number, name in ((1, "OP 1 ROUGH T1"), (2, "OP 2 FINISH T1")):
        feed, rapid = feed_and_rapid(drawn_operations(figure)[name])
        assert (feed.get_linestyle(), rapid.get_linestyle()) == ("-", "--")
        blocks = operation_lines(program, number)
        assert all(has_vertex(rapid, point) for point in points(blocks, (0,))), name
        assert all(has_vertex(feed, point) for point in points(blocks, FEED_CODES)), name
    legend = " | ".join(text.get_text() for legend in figure.legends for text in legend.get_texts())
    assert "rapid (G0): dashed" in legend and "feed (G1/G2/G3, thread): solid" in legend


def test_the_title_names_job_drawing_machine_and_program(conn, tmp_path):
    seed_drawing(tmp_path / "shaft-7.dxf")
    job_id, program = job_and_program(conn, tmp_path / "shaft-7.dxf")
    title = turning_job_figure(conn, job_id).axes[0].get_title()
    header = dict(line.strip("()").split(" ", 1) for line in program[2:4])   # (DRAWING …), (MACHINE …)
    assert program[1].endswith("(SHAFT_7)")                   # the ISO program's name, after its number
    assert f"job {job_id} " in title
    for said in ("drawing shaft-7.dxf", f"machine {header['MACHINE']}", "program SHAFT_7"):
        assert said in title, (said, title)
    assert header["DRAWING"] == "shaft-7.dxf" and header["MACHINE"] == "lathe-iso"


def test_several_operations_each_have_a_colour_and_the_near_tool_change_point_is_framed(conn, tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    job_id, program = job_and_program(conn, tmp_path / "part.dxf")
    figure = turning_job_figure(conn, job_id)
    drawn = drawn_operations(figure)
    assert sorted(drawn) == ["OP 1 ROUGH T1", "OP 2 SLOT T2", "OP 3 THREAD T3"]
    assert len({feed_and_rapid(lines)[0].get_color() for lines in drawn.values()}) == 3
    tool_change = points(operation_lines(program, 1)[:1], (0,))[0]   # the tool-change block, as written
    assert tool_change == pytest.approx((1 * INCH, 2 * 1.5 * INCH), abs=PRINTED_MM)   # POINT (1, 1.5) in
    marker = tool_change_marker(figure)
    assert vertices(marker) == [pytest.approx(tool_change, abs=PRINTED_MM)]
    assert inside(figure, tool_change) and not figure.axes[0].texts   # near: drawn where it is


def tool_change_marker(figure):
    return next(line for line in figure.axes[0].lines if line.get_label().startswith("tool change Z"))


def inside(figure, point) -> bool:
    (z0, z1), (x0, x1) = figure.axes[0].get_xlim(), figure.axes[0].get_ylim()
    return z0 <= point[0] <= z1 and x0 <= point[1] <= x1


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_limits_frame_the_work_and_point_to_a_far_tool_change(conn):
    job_id, program = hemisphere_job(conn)
    figure = turning_job_figure(conn, job_id)
    tool_change = points(operation_lines(program, 1)[:1], (0,))[0]
    # No POINT in the drawing: 50 mm beyond it (the import's note), axially from its end at Z0 and
    # radially from the blank (the profile's Ø12 + 2 mm).
    assert tool_change == (0.0 + 50.0, 2 * ((12.0 + 2.0) / 2 + 50.0))
    everything = points(program, (0, *FEED_CODES))
    # The work: every position of the program but the travel at the tool-change diameter; and the axis.
    work = [point for point in everything if point[1] != tool_change[1]] + [(0.0, 0.0)]
    assert all(inside(figure, point) for point in work)
    (z0, z1), (x0, x1) = figure.axes[0].get_xlim(), figure.axes[0].get_ylim()
    zs, xs = [z for z, _ in work], [x for _, x in work]
    larger = max(max(zs) - min(zs), (max(xs) - min(xs)) / 2)   # mm, the diameter halved to a radius
    margins = (min(zs) - z0, z1 - max(zs), (min(xs) - x0) / 2, (x1 - max(xs)) / 2)
    assert all(margin <= 0.05 * larger for margin in margins), (margins, larger)
    assert not inside(figure, tool_change)
    assert vertices(tool_change_marker(figure)) == [tool_change]
    note = [text.get_text() for text in figure.axes[0].texts]
    assert note == ["tool change\nZ50 X114"]


def test_alternated_operations_are_drawn_as_one(conn, tmp_path):
    two_rough_layers(tmp_path / "wheel.dxf")
    job_id, program = job_and_program(conn, tmp_path / "wheel.dxf", alternate=[1, 2])
    drawn = drawn_operations(turning_job_figure(conn, job_id))
    assert sorted(drawn) == ["OP 1+2 ROUGH alternated T1"]
    feed, _ = feed_and_rapid(drawn["OP 1+2 ROUGH alternated T1"])
    assert operation_lines(program, 2) == []
    assert all(has_vertex(feed, point) for point in points(operation_lines(program, 1), FEED_CODES))


def test_plot_command_writes_svg_and_names_each_operation(run, tmp_path):
    made = run("import-dxf", DXF / HEMISPHERE, "--rough-depth", "1", "--program-name", "EMCO_G02", "--json")
    job_id = json.loads(made.stdout)["job_id"]
    result = run("plot", "--job", job_id, "-o", tmp_path / "job.svg", "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert [line.split(":")[0] for line in report["drawn"]] == ["operation 1 ROUGH T1", "operation 2 FINISH T1"]
    text = (tmp_path / "job.svg").read_text()
    assert "<svg" in text[:2000] and "X diameter (mm)" in text
