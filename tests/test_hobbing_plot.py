"""`engine plot` for hobbing (issue 17): every sample gear's program drawn from the simulation's
reading, the drawing read back from the figure before it is saved. Expected numbers come from the
gear and hob records by the reference formulas (docs/reference/hobbing.md §B3) or from the
program text, read here with a few lines of its own."""
from __future__ import annotations

import json
import math
import re

import psycopg
import pytest
from helpers.outcomes import made, one_line_error

from engine.hobbing.choices import Choices
from engine.hobbing.program_plot import load_scene, program_figure
from engine.programs.instantiate import instantiate_gear

SAMPLES = [   # gear, what, job choices: every hobbing class the samples hold
    (42, "spur", Choices()), (42, "spur conventional", Choices(feed_mode="conventional")),
    (42, "spur shift per part", Choices(shift_per_part=2.0)), (45, "spur rough + finish", Choices()),
    (46, "spur 2-start hob", Choices()), (43, "helical right hand", Choices()), (44, "helical left hand", Choices()),
    (47, "helical conventional-climb", Choices(feed_mode="conventional-climb", cuts=2)), (50, "taper", Choices()),
    (51, "crowned", Choices()), (53, "worm wheel radial", Choices()),
    (53, "worm wheel tangential", Choices(worm_feed="tangential")), (54, "duplex", Choices()),
]
CYLINDRICAL = [case for case in SAMPLES if case[0] in (42, 43, 44, 45, 46, 47, 54)]
WORD = re.compile(r"\b([XYZ])=?(-?\d+(?:\.\d*)?)")


def drawn(conn, gear_id: int, choices: Choices):
    program = instantiate_gear(conn, gear_id, choices=choices)
    figure, lines = program_figure(load_scene(conn, program.program_id))
    return program, figure, lines


def artists(axes, gid: str) -> list:
    return [a for a in [*axes.patches, *axes.lines, *axes.texts] if a.get_gid() == gid]


def artist(axes, gid: str):
    found = artists(axes, gid)
    assert len(found) == 1, f"{gid!r}: {len(found)} drawn"
    return found[0]


def units_of(conn, gear_id: int) -> list[tuple]:
    """(name, teeth, face width, tip diameter, root diameter) of every unit, from the records:
    tip d + 2·m and root d − 2.5·m where the record leaves them empty (§B3)."""
    gear = conn.execute("SELECT module, teeth, helix_angle, face_width, tip_diameter, root_diameter FROM gear "
                        "WHERE id = %s", (gear_id,)).fetchone()
    module, teeth, helix = float(gear[0]), gear[1], float(gear[2])
    rows = [(1, teeth, *gear[3:])] + conn.execute(
        "SELECT unit, teeth, face_width, tip_diameter, root_diameter FROM gear_unit WHERE gear_id = %s ORDER BY unit",
        (gear_id,)).fetchall()
    result = []
    for unit, z, width, tip, root in rows:
        d = module * z / math.cos(math.radians(helix))
        result.append((f"unit {unit} ({z} teeth)", z, float(width), float(tip or d + 2 * module),
                       float(root or d - 2.5 * module)))
    return result


def hob_tip(conn, program_id: int) -> float:
    return float(conn.execute("SELECT h.tip_diameter FROM program p JOIN job j ON j.id = p.job_id "
                              "JOIN hob h ON h.id = j.hob_id WHERE p.id = %s", (program_id,)).fetchone()[0])


def words(line: str) -> dict:
    return {axis: float(value) for axis, value in WORD.findall(line.partition(";")[0])}


def z_feeds(lines: list[str]) -> list[float]:
    """The sign of every G1 move along Z, from the program text: where Z stood and where it goes."""
    z, signs = None, []
    for line in lines:
        code = line.partition(";")[0]
        if not re.match(r"G[01]\b", code.strip()):
            continue
        target = words(code).get("Z")
        if target is not None and z is not None and code.strip().startswith("G1") and target != z:
            signs.append(math.copysign(1.0, target - z))
        z = target if target is not None else z
    return signs


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("gear_id, what, choices", SAMPLES, ids=[case[1] for case in SAMPLES])
def test_every_sample_class_is_drawn_with_each_unit_at_its_face_width_and_tip(conn, gear_id, what, choices):
    program, figure, lines = drawn(conn, gear_id, choices)
    side = figure.axes[0]
    for name, _, width, tip, _ in units_of(conn, gear_id):
        xs, zs = zip(*artist(side, name).get_xy()[:4])
        assert max(zs) - min(zs) == pytest.approx(width)
        assert max(xs) - min(xs) == pytest.approx(tip, abs=1e-6)
    assert artist(side, "the fixture") and artists(side, "hob at approach")
    assert "it proves the program" in lines[-1]
    title = figure.get_suptitle()
    assert f"gear {gear_id}" in title and program.name in title and "hobber-840d" in title


@pytest.mark.parametrize("gear_id, what, choices", CYLINDRICAL, ids=[case[1] for case in CYLINDRICAL])
def test_the_hob_at_full_depth_stands_at_the_reference_centre_distance(conn, gear_id, what, choices):
    """a = (d_f2 + d_a0)/2 (§B3), for every unit of the gear (the program writes X to the
    micrometre, so within half of one)."""
    program, figure, _ = drawn(conn, gear_id, choices)
    da0 = hob_tip(conn, program.program_id)
    for name, _, _width, _, root in units_of(conn, gear_id):
        centre = artist(figure.axes[0], f"hob at full depth {name} centre")
        assert centre.get_xdata()[0] == pytest.approx((root + da0) / 2, abs=5e-4)
        outline = artist(figure.axes[0], f"hob at full depth {name}")
        assert min(outline.get_xdata()) == pytest.approx(root / 2, abs=5e-4)   # the hob's tip at the root


@pytest.mark.parametrize("gear_id, what, choices", [case for case in SAMPLES if "worm" not in case[1]],
                         ids=[case[1] for case in SAMPLES if "worm" not in case[1]])
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_each_pass_arrow_points_the_way_the_program_feeds_along_z(conn, gear_id, what, choices):
    """One arrow per `; CUT` of the program, pointing the way that cut's G1 moves go along Z."""
    program, figure, _ = drawn(conn, gear_id, choices)
    arrows = [text for text in figure.axes[0].texts if (text.get_gid() or "").startswith("pass ")]
    text = "\n".join(program.lines)
    cuts = [chunk.splitlines() for chunk in text.split("; CUT")[1:]]
    assert len(arrows) == len(cuts) > 0
    for arrow, cut in zip(arrows, cuts):
        assert {math.copysign(1.0, arrow.xy[1] - arrow.xyann[1])} == set(z_feeds(cut))


def test_conventional_and_climb_passes_point_opposite_ways(conn):
    climb = drawn(conn, 42, Choices())[1].axes[0]
    conventional = drawn(conn, 42, Choices(feed_mode="conventional"))[1].axes[0]

    def direction(axes):
        arrow = next(text for text in axes.texts if (text.get_gid() or "").startswith("pass "))
        return math.copysign(1.0, arrow.xy[1] - arrow.xyann[1])
    assert direction(climb) == -direction(conventional)


def test_a_radial_plunge_and_a_tangential_pass_point_the_way_the_program_feeds(conn):
    radial, figure, _ = drawn(conn, 53, Choices())
    plunge = next(t for t in figure.axes[0].texts if (t.get_gid() or "").startswith("pass "))
    infeed = [words(line)["X"] for line in radial.lines if line.startswith("G1 X")]
    assert plunge.xy[0] == pytest.approx(infeed[-1]) and plunge.xyann[0] > plunge.xy[0]
    tangential, figure, _ = drawn(conn, 53, Choices(worm_feed="tangential"))
    feed = next(t for t in figure.axes[2].texts if (t.get_gid() or "").startswith("pass "))
    pass_y = [words(line)["Y"] for line in tangential.lines if line.startswith("G1 Y")][0]
    assert feed.xy[0] == pytest.approx(pass_y, abs=0.01) and math.copysign(1, feed.xy[0] - feed.xyann[0]) == \
        math.copysign(1, pass_y)


@pytest.mark.parametrize("gear_id, what, choices", [SAMPLES[0], SAMPLES[2], SAMPLES[-1]],
                         ids=["spur", "shift per part", "duplex"])
def test_the_working_area_is_drawn_at_the_programs_g25_and_g26(conn, gear_id, what, choices):
    program, figure, lines = drawn(conn, gear_id, choices)
    lower = words(next(line for line in program.lines if line.startswith("G25")))
    upper = words(next(line for line in program.lines if line.startswith("G26")))
    for axes, gid in zip(figure.axes[:2], ("working area", "overview working area")):
        box = artist(axes, gid)
        assert (box.get_x(), box.get_y()) == pytest.approx((lower["X"], lower["Z"]))
        assert (box.get_width(), box.get_height()) == pytest.approx((upper["X"] - lower["X"], upper["Z"] - lower["Z"]))
    swivel = words(next(line for line in program.lines if line.startswith("G0 A=")).replace("A=", "Y"))["Y"]
    travel = artist(figure.axes[2], "working area Y")
    cos_a = math.cos(math.radians(swivel))
    assert list(travel.get_xdata()) == pytest.approx([lower["Y"] * cos_a, upper["Y"] * cos_a])
    assert any(line.startswith("working area G25") for line in lines)


def test_the_shift_range_covers_the_hob_length_the_shifting_uses(conn):
    """R11 is clamped to −y … +y: the generating zone (§B15, L_gen = 2·2.25·m/tan α + π·m) sweeps
    2y + L_gen of the hob."""
    program, figure, lines = drawn(conn, 42, Choices(shift_per_part=2.0))
    low, high = (float(v) for v in re.search(r"IF \(R11<(-?[\d.]+)\) OR \(R11>(-?[\d.]+)\)",
                                             "\n".join(program.lines)).groups())
    zone = 2 * 2.25 * 2 / math.tan(math.radians(20)) + math.pi * 2
    band = artist(figure.axes[2], "shift range").get_xy()[:4]
    along = max(math.dist(band[0], band[1]), math.dist(band[1], band[2]))
    assert along == pytest.approx(high - low + zone, abs=1e-6)
    assert any(f"Y{low:g} … Y{high:g}" in line for line in lines)


def job_with_program(url: str, gear_id: int = 42) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT max(job_id) FROM program p JOIN job j ON j.id = p.job_id WHERE j.gear_id = %s",
                            (gear_id,)).fetchone()[0]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_plot_writes_png_and_svg_for_a_job_and_a_program(run, tmp_path):
    assert run("instantiate", "--gear", 54).exit_code == 0
    job_id = job_with_program(run.url, 54)
    png, svg = tmp_path / "duplex.png", tmp_path / "duplex.svg"
    result = run("plot", "--job", job_id, "-o", png)
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "unit 2 (19 teeth)" in result.stdout and "hob at full depth" in result.stdout
    with psycopg.connect(run.url) as conn:
        program_id = conn.execute("SELECT max(id) FROM program WHERE job_id = %s", (job_id,)).fetchone()[0]
    assert run("plot", "--program", program_id, "-o", svg).exit_code == 0
    text = svg.read_text(encoding="utf-8")
    assert "<svg" in text[:2000] and 'id="hob at full depth unit 2 (19 teeth)"' in text
    ids = re.findall(r'\bid="([^"]+)"', text)
    assert len(ids) == len(set(ids))      # every drawn thing is named once


def test_a_bad_suffix_or_a_job_without_a_program_is_refused_in_one_line_and_writes_nothing(run, tmp_path):
    assert run("instantiate", "--gear", 42).exit_code == 0
    job_id = job_with_program(run.url)
    result = run("plot", "--job", job_id, "-o", tmp_path / "job.pdf")
    assert result.exit_code == 1 and "FILE.png or FILE.svg" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    with psycopg.connect(run.url) as conn:
        empty = conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params) "
                             "VALUES (42, 'spur', 'hobber-840d', 'H-M2-AA-R1', '{}') RETURNING id").fetchone()[0]
    result = run("plot", "--job", empty, "-o", tmp_path / "empty.png")
    assert result.exit_code == 1 and f"engine instantiate --job {empty}" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    result = run("plot", "--program", 999999, "-o", tmp_path / "none.svg")
    assert result.exit_code == 1 and "program 999999 does not exist" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_turning_program_is_refused_naming_the_plot_of_its_job(run, tmp_path):
    from helpers.drawings import seed_drawing

    seed_drawing(tmp_path / "part.dxf")
    job_id = json.loads(run("import-dxf", tmp_path / "part.dxf", "--json").stdout)["job_id"]
    program_id = json.loads(run("instantiate", "--job", job_id, "--json").stdout)["program_id"]
    result = run("plot", "--program", program_id, "-o", tmp_path / "turned.png")
    assert result.exit_code == 1 and len(result.stderr.strip().splitlines()) == 1
    assert f"engine plot --job {job_id}" in result.stderr
    assert not (tmp_path / "turned.png").exists()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("where", ["/proc/job.png", "NAME_TOO_LONG"], ids=["proc", "name-too-long"])
def test_a_picture_that_cannot_be_written_is_refused_in_one_line_naming_the_file(run, tmp_path, where):
    """/proc takes no new file, and 256 characters are more than a file name may have (Linux: 255):
    the user is told which file and why, and no temporary file is left beside it."""
    target = tmp_path / ("p" * 252 + ".png") if where == "NAME_TOO_LONG" else where
    assert run("instantiate", "--gear", 42).exit_code == 0
    result = run("plot", "--job", job_with_program(run.url), "-o", target)
    assert result.exit_code == 1 and len(result.stderr.strip().splitlines()) == 1, result.output
    assert f"cannot write the picture {str(target)!r}" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_cut_comment_with_dollar_signs_is_drawn_as_written(conn, tmp_path):
    """The legend names each pass by its `; CUT …` comment; matplotlib reads text between two `$`
    as TeX. The picture shows the shop's words as written (the SVG carries each text it draws)."""
    from msgspec.structs import replace

    from engine.pictures import save_atomically
    from engine.simulation.hobbing.recorded import record_program

    program = instantiate_gear(conn, 42, choices=Choices())
    said = [line.replace("; CUT", "; CUT $\\frac$ costs 5 \\$", 1) for line in program.lines]
    scene = load_scene(conn, program.program_id)
    scene = replace(scene, recording=record_program(said, scene.gear, scene.hob, scene.machine, scene.name))
    save_atomically(program_figure(scene)[0], tmp_path / "cut.svg", "svg")
    comments = [line.lstrip("; ") for line in said if line.startswith("; CUT")]
    assert comments and all(comment in (tmp_path / "cut.svg").read_text() for comment in comments)


def draft_of_spur(run, tmp_path) -> None:
    """An editor's draft of the spur template: every `; CUT` comment says TRIAL."""
    exported = run("template", "export", "--class", "spur").stdout
    (tmp_path / "spur.csv").write_text(exported.replace("; CUT {cut_name}", "; CUT {cut_name} TRIAL"))
    assert run("template", "import", "--class", "spur", tmp_path / "spur.csv").exit_code == 0


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_picture_of_a_job_is_of_its_released_program_not_a_draft_tried_on_it(run, tmp_path):
    """The operator's picture of a job shows the program that reaches the machine; a draft is
    drawn only for a job that has nothing else, and then the picture and the report say draft."""
    released = json.loads(run("instantiate", "--gear", 45, "--json").stdout)
    draft_of_spur(run, tmp_path)
    assert run("instantiate", "--job", released["job_id"], "--draft").exit_code == 0
    result = run("plot", "--job", released["job_id"], "-o", tmp_path / "job.svg", "--json")
    drawn_lines = json.loads(result.stdout)["drawn"]
    assert drawn_lines[0].startswith(f"program {released['program_id']} (") and "draft" not in drawn_lines[0]
    assert "TRIAL" not in (tmp_path / "job.svg").read_text()
    only_draft = json.loads(run("instantiate", "--gear", 42, "--draft", "--json").stdout)
    result = run("plot", "--job", only_draft["job_id"], "-o", tmp_path / "draft.svg", "--json")
    drawn_lines = json.loads(result.stdout)["drawn"]
    assert drawn_lines[0].startswith(f"program {only_draft['program_id']} (a draft")
    with psycopg.connect(run.url) as conn:
        figure = program_figure(load_scene(conn, only_draft["program_id"]))[0]
    assert "DRAFT" in figure.get_suptitle() and "TRIAL" in (tmp_path / "draft.svg").read_text()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_picture_of_a_program_the_simulation_refuses_says_so_in_red(conn):
    """The gear's face width corrected after its program was stored (20 → 40 mm): the program no
    longer hobs the whole face, the simulation refuses it, and the picture's title says so first."""
    from matplotlib.colors import same_color

    program = instantiate_gear(conn, 42, choices=Choices())
    proved = program_figure(load_scene(conn, program.program_id))[0]
    assert "REFUSED" not in proved.get_suptitle() and same_color(proved._suptitle.get_color(), "black")
    conn.execute("UPDATE gear SET face_width = 40 WHERE id = 42")
    figure, lines = program_figure(load_scene(conn, program.program_id))
    assert "refuses" in lines[-1]
    assert figure.get_suptitle().startswith("REFUSED BY THE SIMULATION: ")
    assert same_color(figure._suptitle.get_color(), "red")


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_picture_with_a_long_file_name_is_not_a_bug(run, tmp_path):
    """A name of 249 characters is a valid file name (Linux allows 255); the picture is written
    beside it under `.NAME.<random>.png` first, which is too long: OSError, exit 2."""
    program = made(run("instantiate", "--gear", 42, "--json"))
    target = tmp_path / ("p" * 245 + ".png")
    result = run("plot", "--program", program["program_id"], "-o", target)
    assert result.exit_code != 2, result.output
    assert (result.exit_code == 0 and target.is_file()) or one_line_error(result)
    assert [path.name for path in tmp_path.iterdir() if path.suffix == ".png"] in ([], [target.name])


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_cut_comment_with_dollar_signs_is_drawn_not_a_bug(run, tmp_path):
    """The picture's legend takes a cut's label from the program's `; CUT …` comment; matplotlib
    reads text between two $ as TeX, so a draft whose comment says `$\\frac$` stores a program
    (the simulation proves it) that `engine plot` cannot draw: ValueError, exit 2."""
    exported = run("template", "export", "--class", "spur").stdout
    assert exported.count("; CUT {cut_name}") == 2
    edited = tmp_path / "spur.csv"
    edited.write_text(exported.replace("; CUT {cut_name}", "; CUT {cut_name} $\\\\frac$"))
    assert run("template", "import", "--class", "spur", edited).exit_code == 0
    program = made(run("instantiate", "--gear", 42, "--draft", "--json"))
    target = tmp_path / "draft.png"
    result = run("plot", "--program", program["program_id"], "-o", target)
    assert result.exit_code == 0 and target.is_file(), result.output


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_picture_of_a_job_is_of_the_program_that_reaches_the_machine(run, tmp_path):
    """`engine plot --job ID` draws the job's newest program. After an editor tries a draft on
    the job (`instantiate --job ID --draft`), that is the draft's program: the operator's picture
    of the job shows a program that never reaches the machine, and nothing in it says draft."""
    released = made(run("instantiate", "--gear", 45, "--json"))
    exported = run("template", "export", "--class", "spur").stdout
    edited = tmp_path / "spur.csv"
    edited.write_text(exported.replace("; CUT {cut_name}", "; CUT {cut_name} TRIAL"))
    assert run("template", "import", "--class", "spur", edited).exit_code == 0
    draft = made(run("instantiate", "--job", released["job_id"], "--draft", "--json"))
    assert draft["program_id"] != released["program_id"]
    drawn = made(run("plot", "--job", released["job_id"], "-o", tmp_path / "job.png", "--json"))["drawn"]
    assert drawn[0].startswith(f"program {released['program_id']} ") or "draft" in " ".join(drawn).lower(), drawn


def figure_texts(figure) -> str:
    """Every text a reader of the picture sees: titles, legends, annotations."""
    texts = [figure._suptitle.get_text() if figure._suptitle else "", *(t.get_text() for t in figure.texts)]
    for legend in figure.legends:
        texts += [t.get_text() for t in legend.get_texts()]
    for axes in figure.axes:
        texts += [axes.get_title(), *(t.get_text() for t in axes.texts)]
        if axes.get_legend():
            texts += [t.get_text() for t in axes.get_legend().get_texts()]
    return " ".join(texts)


def test_the_picture_of_a_program_the_simulation_refuses_says_so(run):
    """A picture is passed around without the command's output: when the simulation refuses the
    program now (its gear's face width was corrected after it was stored), only stdout says so,
    and the picture looks like that of a proved program."""
    from engine.hobbing.program_plot import load_scene, program_figure

    program = made(run("instantiate", "--gear", 42, "--json"))
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET face_width = 40 WHERE id = 42")
        figure, drawn = program_figure(load_scene(conn, program["program_id"]))
    assert "refuses" in drawn[-1]
    assert "refus" in figure_texts(figure).lower()
