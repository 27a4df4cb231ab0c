"""The sample drawing users copy (issue 17): seed_templates/drawings/sample_shaft.dxf, in the
seed-000 convention, ships with the engine and becomes a job with exactly the operations it
draws. Every expected value is read from the DXF here with ezdxf (codes, tool-change POINT,
paths), and the program is read with tests/helpers/lathe_programs.py, not with the engine's reader."""
from __future__ import annotations

import ast
import fnmatch
import importlib.util
import json
import math
import re
from pathlib import Path

import ezdxf
import psycopg
import pytest
from click.testing import CliRunner
from helpers.lathe_programs import distance_to_drawn, drawn_polylines, motions, operation_lines, words

from engine.cli.app import main
from engine.machines.records import load_machine
from engine.paths import SAMPLE_DRAWING, SEED_DIR, data_folder
from engine.verifier import verify_program
from importers.sample import sample_turning_job

ROOT = Path(__file__).resolve().parent.parent
KINDS = ["ROUGH", "SLOT", "FINISH", "THREAD"]
CODE = re.compile(r"@([A-Z])([^\s@]+)")   # the seed's form, @GROUGH @S1200: letter, value
ON_PROFILE_MM = 0.001      # drawn arcs are flattened within 0.0005 mm (lathe_programs)
SAMPLES_PER_MOVE = 40
CUTS = (1, 2, 3)           # every operation but the thread, which cuts below the drawn crest by design


# ---- the drawing as ezdxf reads it ----------------------------------------------------------

def modelspace():
    return ezdxf.readfile(SAMPLE_DRAWING).modelspace()


def drawn_codes() -> dict[int, dict[str, str]]:
    """{operation layer n: {letter: value as written}} from the TEXT/MTEXT of layers 1 … n."""
    codes: dict[int, dict[str, str]] = {}
    for text in modelspace().query("TEXT MTEXT"):
        if text.dxf.layer.isdecimal():
            codes.setdefault(int(text.dxf.layer), {}).update(CODE.findall(text.plain_text()))
    return codes


def tool_change_point() -> tuple[float, float]:
    """(z, radius) of the one POINT on layer 0."""
    [point] = modelspace().query('POINT[layer=="0"]')
    return point.dxf.location.x, point.dxf.location.y


def drawn_lines(layer: str) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    return [((line.dxf.start.x, line.dxf.start.y), (line.dxf.end.x, line.dxf.end.y))
            for line in modelspace().query(f'LINE[layer=="{layer}"]')]


def drawn_vertices(layer: str) -> list[tuple[float, float]]:
    """The vertices of the layer's polylines, in the order drawn."""
    return [tuple(point) for polyline in modelspace().query(f'LWPOLYLINE[layer=="{layer}"]')
            for point in polyline.get_points("xy")]


# ---- the job and its program ------------------------------------------------------------------

def imported(run) -> tuple[dict, dict, dict, list[str]]:
    """`engine import-dxf` of the shipped file, then `engine instantiate --job`: (report, params,
    module_params, program lines)."""
    made = run("import-dxf", SAMPLE_DRAWING, "--json")
    assert made.exit_code == 0, made.output
    report = json.loads(made.stdout)
    program = run("instantiate", "--job", report["job_id"])
    assert program.exit_code == 0, program.output
    with psycopg.connect(run.url) as conn:
        params, module_params = conn.execute("SELECT params, module_params FROM job WHERE id = %s",
                                             (report["job_id"],)).fetchone()
    return report, params, module_params, program.stdout.splitlines()


def feeds(lines: list[str], gs=(1, 2, 3)) -> list[tuple[int, tuple, tuple, str]]:
    """(G, start, end, block) of the operation's cutting moves, start/end as (z, radius)."""
    moving = [line for line in lines if words(line).get("G") in (0, 1, 2, 3, 32) and
              ("X" in words(line) or "Z" in words(line))]
    return [(g, a, b, block) for (g, a, b), block in zip(motions(lines), moving[1:]) if g in gs]


def points_along(g: int, start, end, block: str) -> list[tuple[float, float]]:
    """Points of a G0/G1 line or a G2/G3 arc (R word, the short way), ends included."""
    steps = [k / SAMPLES_PER_MOVE for k in range(SAMPLES_PER_MOVE + 1)]
    if g in (0, 1):
        return [(start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1])) for t in steps]
    centre, radius = arc_centre(g, start, end, words(block)["R"])
    a0, a1 = (math.atan2(p[1] - centre[1], p[0] - centre[0]) for p in (start, end))
    sweep = (a1 - a0) % (2 * math.pi) if g == 3 else -((a0 - a1) % (2 * math.pi))
    return [(centre[0] + radius * math.cos(a0 + t * sweep), centre[1] + radius * math.sin(a0 + t * sweep))
            for t in steps]


def arc_centre(g: int, start, end, radius: float):
    """G3 runs counter-clockwise with Z to the right and the radius up: its centre lies left of the chord."""
    dz, dr = end[0] - start[0], end[1] - start[1]
    chord = math.hypot(dz, dr)
    height = math.sqrt(max(radius * radius - chord * chord / 4, 0.0)) * (1 if g == 3 else -1)
    middle = ((start[0] + end[0]) / 2, (start[1] + end[1]) / 2)
    return (middle[0] - dr / chord * height, middle[1] + dz / chord * height), radius


def inside_part(point, outline: list[tuple[float, float]]) -> bool:
    """Even-odd test against the drawn half-profile, closed along the axis."""
    z, r = point
    edges = zip(outline, outline[1:] + outline[:1])
    crossings = sum(1 for (z0, r0), (z1, r1) in edges
                    if min(z0, z1) <= z < max(z0, z1) and r0 + (z - z0) * (r1 - r0) / (z1 - z0) > r)
    return crossings % 2 == 1


def gouges(lines: list[str], outline, polylines) -> list[str]:
    """Blocks with a point inside the part farther than ON_PROFILE_MM from its outline."""
    return [block for g, a, b, block in feeds(lines, (0, 1, 2, 3))
            if any(inside_part(point, outline) and distance_to_drawn(point, polylines) > ON_PROFILE_MM
                   for point in points_along(g, a, b, block))]


# ---- tests ------------------------------------------------------------------------------------

def test_the_sample_becomes_rough_slot_finish_thread_with_the_codes_it_draws(run):
    report, params, module_params, _ = imported(run)
    codes = drawn_codes()
    assert sorted(codes) == [1, 2, 3, 4] and [codes[n]["G"] for n in sorted(codes)] == KINDS
    assert [(op["operation"], op["kind"]) for op in report["operations"]] == list(enumerate(KINDS, start=1))
    for n, written in codes.items():
        assert module_params[f"prep:{n}"]["tool"] == int(written["T"])
        assert module_params[f"cutcond:{n}"]["spindle_rpm"] == float(written["S"])
        assert module_params[f"cutcond:{n}"]["coolant"] is (written["M"] == "8")
        assert module_params[f"cutmotion:{n}"].get("feed") == (float(written["F"]) if "F" in written else None)
    thread = module_params["cutmotion:4"]
    assert [thread[name] for name in ("thread_pitch", "depth_per_pass", "infeed_angle")] == [
        float(codes[4][letter]) for letter in "PDA"]
    z, radius = tool_change_point()
    assert (params["tool_change_z"], params["tool_change_x"]) == (z, 2 * radius)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_program_changes_tools_at_the_drawn_point_and_passes_the_lathe_checks(run):
    _, params, _, lines = imported(run)
    z, radius = tool_change_point()
    tool_change = f"G00 X{2 * radius:.3f} Z{z:.3f}"
    tools = [number for number, line in enumerate(lines) if re.fullmatch(r"T\d{4}", line)]
    assert len(tools) == 4 and all(lines[number - 1] == tool_change for number in tools)
    assert lines[-4] == tool_change          # back there before M05 M30 %
    with psycopg.connect(run.url) as conn:
        verify_program(lines, load_machine(conn, "lathe-iso"), params["program_name"])   # raises if refused
    polylines = drawn_polylines(SAMPLE_DRAWING)
    [outline] = polylines
    for n in CUTS:
        assert gouges(operation_lines(lines, n), outline, polylines) == [], n


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_each_operation_cuts_what_its_layer_draws(run):
    _, _, _, lines = imported(run)
    polylines = drawn_polylines(SAMPLE_DRAWING)
    rough = [(a, b) for _, a, b, _ in feeds(operation_lines(lines, 1)) if a[1] == b[1]]
    assert sorted(rough) == sorted(drawn_lines("1"))
    plunges = [b for _, _, b, _ in feeds(operation_lines(lines, 2))]
    assert sorted(plunges) == sorted(min(line, key=lambda p: p[1]) for line in drawn_lines("2"))
    finish = feeds(operation_lines(lines, 3))
    assert [b for _, _, b, _ in finish] == drawn_vertices("3")   # the lead-in feeds onto each path's start
    for g, a, b, block in finish:
        on_path = points_along(g, a, b, block) if a in drawn_vertices("3") else [b]
        assert max(distance_to_drawn(p, polylines) for p in on_path) <= ON_PROFILE_MM, block
    check_thread(operation_lines(lines, 4))


def check_thread(lines: list[str]) -> None:
    """ceil(depth / @D) passes of the pitch @P, the last at the drawn root, each to the drawn end."""
    codes = drawn_codes()[4]
    (crest, root) = sorted({line[0][1] for line in drawn_lines("4")}, reverse=True)
    end_z = min(point[0] for line in drawn_lines("4") for point in line)
    cuts = feeds(lines, (32,))
    assert len(cuts) == math.ceil(round((crest - root) / float(codes["D"]), 9))
    assert all(b[0] == end_z and words(block)["F"] == float(codes["P"]) for _, _, b, block in cuts)
    assert cuts[-1][2][1] == root


def test_the_demo_makes_the_sample_a_job_from_a_blank_it_never_rapids_through(conn):
    sample = sample_turning_job(conn)
    assert sample.drawing == SAMPLE_DRAWING
    assert [op["kind"] for op in sample.job.operations] == KINDS
    lines = sample.program.lines
    assert lines[-2:] == ["M30", "%"]
    stock = conn.execute("SELECT params->'stock_diameter' FROM job WHERE id = %s", (sample.job.job_id,)).fetchone()[0]
    drawn = [r for layer in ("0", "1") for line in drawn_lines(layer) for _, r in line]
    assert stock >= 2 * max(drawn + [r for line in drawn_polylines(SAMPLE_DRAWING) for _, r in line])
    along_z = [(a, b) for g, a, b, _ in feeds(lines, (0,)) if a[0] != b[0]]
    assert along_z and all(2 * min(a[1], b[1]) >= stock for a, b in along_z)


def test_the_installed_package_finds_the_sample_where_setup_py_ships_it(tmp_path):
    assert SAMPLE_DRAWING == ROOT / "seed_templates" / "drawings" / "sample_shaft.dxf" and SAMPLE_DRAWING.is_file()
    folders, patterns = shipped_data()
    folder = SAMPLE_DRAWING.parent.relative_to(ROOT).as_posix()
    package = next(name for name, source in folders.items() if source == folder)
    assert any(fnmatch.fnmatch(SAMPLE_DRAWING.name, pattern) for pattern in patterns)
    site = tmp_path / "site-packages"
    installed = site.joinpath(*package.split("."), SAMPLE_DRAWING.name)
    assert installed == data_folder("seed_templates", site) / SAMPLE_DRAWING.relative_to(SEED_DIR)


def shipped_data() -> tuple[dict[str, str], list[str]]:
    """setup.py's DATA_FOLDERS (package → folder) and the file patterns it ships of them."""
    tree = ast.parse((ROOT / "setup.py").read_text(encoding="utf-8"))
    folders = next(ast.literal_eval(node.value) for node in ast.walk(tree)
                   if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "DATA_FOLDERS")
    patterns = next(ast.literal_eval(node.value) for node in ast.walk(tree) if isinstance(node, ast.DictComp))
    return folders, patterns


def test_the_committed_drawing_is_what_its_generator_writes(tmp_path):
    spec = importlib.util.spec_from_file_location("make_sample", SAMPLE_DRAWING.parent / "make_sample.py")
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    written = generator.sample_drawing(tmp_path / SAMPLE_DRAWING.name)
    assert entities(written) == entities(SAMPLE_DRAWING)


def entities(path: Path) -> list[tuple]:
    """Each model-space entity as (type, layer, its defining numbers or text), in file order."""
    found = []
    for entity in ezdxf.readfile(path).modelspace():
        kind = entity.dxftype()
        if kind == "LWPOLYLINE":
            shape = tuple(map(tuple, entity.get_points("xyb")))
        elif kind in ("TEXT", "MTEXT"):
            shape = entity.plain_text()
        else:
            shape = tuple(tuple(value) if hasattr(value, "__iter__") else value
                          for value in entity.dxfattribs(drop={"handle", "owner", "layer"}).values())
        found.append((kind, entity.dxf.layer, shape))
    return found


def test_demo_turning_with_a_gear_is_refused_in_one_line(monkeypatch):
    monkeypatch.setattr("engine.programs.demo.run_demo", lambda *args: pytest.fail("the demo ran"))
    result = CliRunner().invoke(main, ["demo", "--turning", "--gear", "43"])
    assert result.exit_code == 1 and len(result.stderr.strip().splitlines()) == 1
    assert "--gear and --turning exclude each other" in result.stderr
