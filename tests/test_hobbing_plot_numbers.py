"""`engine plot` of a hobbing program states what an operator checks the set-up against (issue
27): the swivel A with its sign as the program writes it, per cut the centre distance and depth,
the feeds as programmed, the shift range; it draws the gear's teeth beside the hob's thread at
the programmed swivel so a wrong hand shows, and a worm wheel from above with both of its
motions. Expected numbers are computed here from the records by the reference formulas
(docs/reference/hobbing.md §A7, §B1–§B5, §B10) or read from the program text with a few lines
of this file's own; the picture's texts are read from the figure before it is saved."""
from __future__ import annotations

import math
import re

import pytest
from helpers.outcomes import made
from msgspec.structs import replace

from engine.hobbing.choices import Choices
from engine.hobbing.program_plot import load_scene, program_figure
from engine.programs.instantiate import instantiate_gear
from engine.simulation.hobbing.recorded import record_program

HOB_DEDENDUM = 1.25            # d_m0 = d_a0 − 2·1.25·m_n (§B1)
NUMBERS = "numbers read from the program"
HAND = "hand check"
TOP = "worm wheel from above"
FLIPPED_A = "hobber-a-flip"    # hobber-840d with its swivel turning the other way (a_direction −1)


def hand(letter) -> int:
    return -1 if letter == "L" else 1


def records(conn, program_id: int) -> dict:
    """The gear's and hob's facts the reference formulas take."""
    row = conn.execute(
        "SELECT g.module, g.teeth, g.helix_angle, g.hand, g.tip_diameter, g.root_diameter, h.starts, "
        "h.tip_diameter, h.hand FROM program p JOIN job j ON j.id = p.job_id JOIN gear g ON g.id = j.gear_id "
        "JOIN hob h ON h.id = j.hob_id WHERE p.id = %s", (program_id,)).fetchone()
    keys = ("m", "z2", "beta", "gear_hand", "da2", "df2", "z0", "da0", "hob_hand")
    return {key: float(value) if key not in ("gear_hand", "hob_hand") else value for key, value in zip(keys, row)}


def lead_angle(r: dict) -> float:
    """γ: sin γ = z0·m_n/d_m0 (§B1)."""
    return math.degrees(math.asin(r["z0"] * r["m"] / (r["da0"] - 2 * HOB_DEDENDUM * r["m"])))


def swivel(r: dict) -> float:
    """A = h_hob·γ − h_gear·β in the DIN frame (§A7)."""
    return hand(r["hob_hand"]) * lead_angle(r) - hand(r["gear_hand"]) * r["beta"]


def panel(figure, title: str):
    return next(axes for axes in figure.axes if axes.get_title().startswith(title))


def texts(axes) -> dict:
    return {text.get_gid(): text.get_text() for text in axes.texts}


def numbers_text(figure) -> str:
    return " ".join(" ".join(texts(panel(figure, NUMBERS)).values()).split())


def number_after(text: str, word: str) -> list[float]:
    return [float(value) for value in re.findall(re.escape(word) + r"(-?\d+\.\d+)", text)]


def line_of(axes, gid: str):
    return next(line for line in axes.lines if line.get_gid() == gid)


def direction(axes, gid: str) -> float:
    """The direction of a drawn line, degrees from +Y toward +Z, as an undirected line (0…180)."""
    xs, ys = line_of(axes, gid).get_xdata(), line_of(axes, gid).get_ydata()
    return math.degrees(math.atan2(ys[1] - ys[0], xs[1] - xs[0])) % 180.0


def figure_of(conn, gear_id: int, choices: Choices = Choices(), machine: str | None = None):
    program = instantiate_gear(conn, gear_id, machine=machine, choices=choices)
    figure, drawn = program_figure(load_scene(conn, program.program_id))
    return program, figure, drawn


def written(lines: list[str], pattern: str) -> list[float]:
    return [float(value) for line in lines for value in re.findall(pattern, line.partition(";")[0])]


@pytest.mark.parametrize("gear_id", [43, 44], ids=["right-hand gear", "left-hand gear"])
def test_the_picture_states_swivel_centre_distance_depth_feeds_and_shift_of_the_program(conn, gear_id):
    """A = h_hob·γ − h_gear·β with its sign (−(β − γ) for a right-hand gear cut with a right-hand
    hob, +(β − γ) for left with left); a = (d_f2 + d_a0)/2, depth (d_a2 − d_f2)/2 (§B3); the F
    the program writes in mm/min and f = v_f/n2, n2 = S·z0/z2 (§B5); Y where the hob stands."""
    program, figure, drawn = figure_of(conn, gear_id)
    r, text = records(conn, program.program_id), numbers_text(figure)
    wanted = swivel(r)
    assert math.copysign(1, wanted) == -hand(r["gear_hand"]) and abs(wanted) == pytest.approx(r["beta"] - lead_angle(r))
    assert number_after(text, "swivel A=") == [pytest.approx(wanted, abs=5e-4)]
    assert ("A=-" in text) == (wanted < 0) and f"DIN {wanted:+.3f}°" in text
    assert number_after(text, "centre distance X") == [pytest.approx((r["df2"] + r["da0"]) / 2, abs=5e-4)]
    assert number_after(text, "depth ") == [pytest.approx((r["da2"] - r["df2"]) / 2, abs=1e-3)]
    table = written(program.lines, r"\bS(\d+)")[0] * r["z0"] / r["z2"]
    for feed in written(program.lines, r"^G1 .*F(\d+\.?\d*)"):
        assert f"F{feed:g} mm/min ({feed / table:.3f} mm/rev of the work)" in text
    stands = written(program.lines, r"^G0 Y(-?\d+\.\d+)")
    assert f"Y{stands[0]:.3f} mm for every part" in text
    assert any(line.startswith("swivel A=") for line in drawn)


def test_a_left_hand_gear_is_drawn_with_its_teeth_and_swivel_the_other_way(conn):
    """Seen from the hob, a right-hand helix rises to the right at β from the work axis (at +X it
    runs +Y as it rises) and a left-hand one to the left; the hob axis stands at A from Y and its
    thread at the gear at 90° − h_hob·γ + A, along the teeth when A is right (§A7)."""
    angles = {}
    for gear_id in (43, 44):
        program, figure, _ = figure_of(conn, gear_id)
        r, hand_check = records(conn, program.program_id), panel(figure, HAND)
        teeth = direction(hand_check, "hand gear teeth")
        assert teeth == pytest.approx(90 - hand(r["gear_hand"]) * r["beta"], abs=1e-6)
        assert direction(hand_check, "hand hob axis") == pytest.approx(swivel(r) % 180, abs=1e-3)
        assert direction(hand_check, "hand hob thread") == pytest.approx(teeth, abs=1e-3)
        assert direction(hand_check, "hand coupling helix") == pytest.approx(teeth, abs=1e-3)
        assert "lies along the teeth" in texts(hand_check)["hand verdict"]
        angles[r["gear_hand"]] = (teeth, swivel(r))
    assert angles["R"][0] < 90 < angles["L"][0] and angles["R"][1] < 0 < angles["L"][1]


def test_a_swivel_written_with_the_wrong_sign_shows_the_thread_across_the_teeth(conn):
    """The program's A negated (a machine's swivel sense taken the wrong way round): the picture
    states the A written, the thread crosses the teeth by 2·|A| and says so in red, and the
    simulation refuses the program (the title)."""
    program = instantiate_gear(conn, 43, choices=Choices())
    r = records(conn, program.program_id)
    wrong = -round(swivel(r), 3)       # as the program writes it: 3 decimals
    lines = [re.sub(r"A=-?\d+\.\d+", f"A={wrong:.3f}", line) for line in program.lines]
    scene = load_scene(conn, program.program_id)
    scene = replace(scene, recording=record_program(lines, scene.gear, scene.hob, scene.machine, scene.name))
    figure, _ = program_figure(scene)
    assert number_after(numbers_text(figure), "swivel A=") == [pytest.approx(wrong, abs=5e-4)]
    hand_check = panel(figure, HAND)
    apart = direction(hand_check, "hand hob thread") - direction(hand_check, "hand gear teeth")
    assert abs(apart) == pytest.approx(2 * abs(wrong), abs=2e-3)
    verdict = texts(hand_check)["hand verdict"]
    assert "CROSSES THE TEETH" in verdict and f"{2 * abs(wrong):.3f}°" in verdict
    assert f"A={swivel(r):.3f}°" in " ".join(verdict.split())
    assert figure.get_suptitle().startswith("REFUSED BY THE SIMULATION")


def add_machine_with_reversed_swivel(conn) -> None:
    conn.execute("CREATE TEMP TABLE flipped ON COMMIT DROP AS SELECT * FROM machine WHERE name = 'hobber-840d'")
    conn.execute("UPDATE flipped SET name = %s, a_direction = -1", (FLIPPED_A,))
    conn.execute("INSERT INTO machine SELECT * FROM flipped")


def test_a_machine_whose_swivel_turns_the_other_way_shows_the_sign_the_program_writes(conn):
    """a_direction −1: the program writes −A (§A7); the picture states the A written, the DIN
    value and the sense, and the thread still lies along the teeth."""
    add_machine_with_reversed_swivel(conn)
    program, figure, _ = figure_of(conn, 43, machine=FLIPPED_A)
    wanted = swivel(records(conn, program.program_id))
    assert written(program.lines, r"A=(-?\d+\.\d+)") == [pytest.approx(-wanted, abs=5e-4)]
    text = numbers_text(figure)
    assert number_after(text, "swivel A=") == [pytest.approx(-wanted, abs=5e-4)]
    assert f"DIN {wanted:+.3f}°, a_direction -1" in text
    assert "lies along the teeth" in texts(panel(figure, HAND))["hand verdict"]


def arrows(axes, prefix: str) -> list:
    return [text for text in axes.texts if (text.get_gid() or "").startswith(prefix)]


def test_a_tangential_worm_wheel_shows_its_radial_infeed_and_its_tangential_pass(conn):
    """§B10: the hob goes to the centre distance a = (d_f2 + d_a0)/2 beside the wheel, then feeds
    along Y through it. Seen from above both motions are drawn where the program makes them, and
    the numbers say both, with their F."""
    program, figure, drawn = figure_of(conn, 53, Choices(worm_feed="tangential"))
    r = records(conn, program.program_id)
    a = (r["df2"] + r["da0"]) / 2
    top, text = panel(figure, TOP), numbers_text(figure)
    (infeed,) = arrows(top, "top radial infeed")
    (tangential,) = arrows(top, "top tangential pass")
    first_feed = next(n for n, line in enumerate(program.lines) if line.startswith("G1 X"))
    x_air = written(program.lines[first_feed - 1:first_feed], r"^G0 X(\d+\.\d+)$")[0]   # where the infeed begins
    y_stands, y_end = written(program.lines, r"^G0 Y(-?\d+\.\d+)")[0], written(program.lines, r"^G1 Y(-?\d+\.\d+)")[0]
    assert infeed.xy == pytest.approx((a, y_stands), abs=5e-4) and infeed.xyann[0] > infeed.xy[0]
    assert tangential.xyann == pytest.approx((a, y_stands), abs=5e-4)
    assert tangential.xy == pytest.approx((a, y_end), abs=5e-4)
    assert number_after(text, "centre distance X") == [pytest.approx(a, abs=5e-4)]
    feeds = written(program.lines, r"^G1 .*F(\d+\.?\d*)")
    assert f"radial infeed X{x_air:.3f} → X{a:.3f} at F{feeds[0]:g} mm/min" in text
    assert f"tangential pass Y{y_stands:.3f} → Y{y_end:.3f} at F{feeds[1]:g} mm/min" in text
    assert "shift: none (Y is the tangential feed)" in text
    assert sum("radial infeed" in line or "tangential pass" in line for line in drawn) >= 2


def test_a_radial_worm_wheel_in_two_cuts_shows_both_plunges(conn):
    """Rough then finish: two plunges along X, the finish one to a = (d_f2 + d_a0)/2, each drawn
    from above and stated with its centre distance and depth (d_a2 + d_a0)/2 − X."""
    program, figure, _ = figure_of(conn, 53, Choices(cuts=2))
    r = records(conn, program.program_id)
    plunges = written(program.lines, r"^G1 X(\d+\.\d+)")
    assert len(plunges) == 2 and plunges[1] == pytest.approx((r["df2"] + r["da0"]) / 2, abs=5e-4)
    ends = [arrow.xy[0] for arrow in arrows(panel(figure, TOP), "top radial infeed")]
    assert ends == pytest.approx(plunges)
    text = numbers_text(figure)
    assert number_after(text, "centre distance X") == pytest.approx(plunges)
    assert number_after(text, "depth ") == pytest.approx([(r["da2"] + r["da0"]) / 2 - x for x in plunges], abs=1e-3)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_shift_range_is_the_programs_r11_clamp(conn):
    """Shift per part: the hob cuts between the clamp's ends (§B15), the program's own values."""
    program, figure, _ = figure_of(conn, 42, Choices(shift_per_part=2.0))
    low, high = (float(v) for v in re.search(r"IF \(R11<(-?[\d.]+)\) OR \(R11>(-?[\d.]+)\)",
                                             "\n".join(program.lines)).groups())
    assert f"shift range: Y{low:.3f} … Y{high:.3f} mm" in numbers_text(figure)


def test_a_cylindrical_gear_has_no_view_from_above(conn):
    _, figure, _ = figure_of(conn, 43)
    assert not [axes for axes in figure.axes if axes.get_title().startswith(TOP)]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_svg_and_the_report_carry_the_numbers(run, tmp_path):
    """The picture is passed around as a file: its text holds the A written, and the command's
    report the same lines."""
    program = made(run("instantiate", "--gear", 43, "--json"))
    svg = tmp_path / "p.svg"
    drawn = made(run("plot", "--program", program["program_id"], "-o", svg, "--json"))["drawn"]
    swivel_line = next(line for line in drawn if line.startswith("swivel A="))
    a_written = swivel_line.split()[1].rstrip("°")
    picture = svg.read_text(encoding="utf-8")
    assert a_written in picture and "numbers read from the program" in picture and "hand check" in picture
    assert any(line.startswith("hand check: the hob's thread lies along the teeth") for line in drawn)


def test_a_taper_states_the_centre_distance_from_one_end_of_its_pass_to_the_other(conn):
    """§B12: the pass moves X with Z along the cone (a polyline of `G1 X… Z…`, issue 29); the
    picture gives the centre distance from least to most along the pass, as the program writes
    the pass's X: the infeed's, where it starts, and its vertices'."""
    program, figure, _ = figure_of(conn, 50)
    infeed = written(program.lines, r"^G1 X(\d+\.\d+) F")
    slant = written(program.lines, r"^G1 X(\d+\.\d+) Z")
    assert len(infeed) == 1 and len(slant) >= 12
    low, high = min(infeed + slant), max(infeed + slant)
    assert f"centre distance X{low:.3f} … X{high:.3f} mm along the pass" in numbers_text(figure)
