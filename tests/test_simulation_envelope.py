"""The hob envelope's nearest point (engine.simulation.hobbing.envelope: the ellipse's foot of
the normal, clamped between the end faces, issue 28) against a reference worked out here from
the cylinder's definition alone, and the batch's pruned numpy path against the plain floats on
whole programs.

The reference: a point p lies in the hob (centre C, axis u = (0, cos A, sin A), radius R,
length L) where |(p − C)·u| ≤ L/2 and |p − C|² − ((p − C)·u)² ≤ R². At height z and a given y,
(p − C)·u does not depend on x, so the hob holds an interval of x, and its point nearest the
work axis is x clamped into it. The least distance over y is found by sampling y densely over
everything the hob can reach and sampling again around the best sample, down to 1e-10 mm: the
distance is convex in y (the slice is convex), so the least lies within a sample of the best."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs import verified_run
from engine.programs.instantiate import instantiate_gear
from engine.simulation.hobbing import contact, envelope_arrays
from engine.simulation.hobbing.envelope import HobBody, nearest_radius
from engine.simulation.hobbing.run import simulate_program

AGREE = 1e-6            # mm
SAMPLES = 2001          # per sampling round
ROUNDS = 8              # each narrows the window to 4 samples of the last: 1e-10 mm after these


def hob_centre(x: float, y: float, z: float, swivel: float) -> tuple[float, float, float]:
    """Machine X, Y (along the hob axis, on the swivel head), Z to the hob centre (reference §A6)."""
    a = math.radians(swivel)
    return x, y * math.cos(a), z + y * math.sin(a)


def distance_at(y, case: dict, height: float):
    """The least distance from the work axis of the hob's points at (·, y, height), inf where the
    hob has none: its interval of x from the cylinder's two conditions."""
    a = math.radians(case["swivel"])
    cx, cy, cz = case["centre"]
    axial = (y - cy) * math.cos(a) + (height - cz) * math.sin(a)
    across = (y - cy) ** 2 + (height - cz) ** 2 - axial ** 2
    inside = (np.abs(axial) <= case["length"] / 2) & (across <= case["radius"] ** 2)
    half = np.sqrt(np.maximum(case["radius"] ** 2 - across, 0.0))
    x = np.clip(0.0, cx - half, cx + half)
    return np.where(inside, np.hypot(x, y), np.inf)


def reference(case: dict, height: float) -> float:
    """The least of distance_at over y, by sampling and sampling again around the best."""
    cy = case["centre"][1]
    reach = case["length"] / 2 + case["radius"]          # the hob reaches no farther along Y
    low, high = cy - reach, cy + reach
    best = math.inf
    for _ in range(ROUNDS):
        ys = np.linspace(low, high, SAMPLES)
        found = distance_at(ys, case, height)
        at = int(np.argmin(found))
        if not np.isfinite(found[at]):
            return math.inf
        best = min(best, float(found[at]))
        step = (high - low) / (SAMPLES - 1)
        low, high = ys[at] - 2 * step, ys[at] + 2 * step
    return best


def random_cases(seed: int, count: int) -> list[dict]:
    """Hobs, swivels (level, nearly level, helical, steep) and centres, some with the work axis
    passing through the hob."""
    rng = np.random.default_rng(seed)
    swivels = [0.0, 1e-4, -0.5, 1.5, 3.0, -20.0, 35.0, -60.0]
    cases = []
    for i in range(count):
        radius, length = rng.uniform(15, 60), rng.uniform(40, 220)
        swivel = swivels[i] if i < len(swivels) else float(rng.uniform(-60, 60))
        x = float(rng.uniform(0.0, 2.5 * radius) if i % 5 == 0 else rng.uniform(radius, 180))
        centre = hob_centre(x, float(rng.uniform(-70, 70)), float(rng.uniform(-80, 40)), swivel)
        cases.append({"radius": radius, "length": length, "swivel": swivel, "centre": centre})
    return cases


def heights_of(case: dict, rng) -> list[float]:
    """Heights across the hob's reach along Z (and a few beyond it, where it has no point)."""
    a = math.radians(case["swivel"])
    extent = case["radius"] * abs(math.cos(a)) + case["length"] / 2 * abs(math.sin(a))
    cz = case["centre"][2]
    inside = cz + extent * rng.uniform(-0.98, 0.98, 12)
    return [*inside.tolist(), cz, cz + 1.05 * extent, cz - 1.2 * extent]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_nearest_point_agrees_with_dense_sampling_of_the_cylinder(seed):
    rng = np.random.default_rng(seed + 100)
    for case in random_cases(seed, 40):
        assert_agrees_with_sampling(case, heights_of(case, rng))


def assert_agrees_with_sampling(case: dict, heights: list[float]) -> None:
    """The plain floats and the numpy path, at each height, against the reference (both inf where
    the hob has no point there)."""
    body = HobBody(case["radius"], case["length"] / 2)
    cx, cy, cz = case["centre"]
    arrays = envelope_arrays.nearest_radius(body, case["swivel"], np.array([[cx]]), np.array([[cy]]),
                                            np.array([[cz]]), np.array([heights]))[0]
    for height, together in zip(heights, arrays):
        expected = reference(case, height)
        plain = nearest_radius(body, case["swivel"], cx, cy, cz, height)
        if math.isinf(expected):
            assert math.isinf(plain) and math.isinf(together), (case, height)
        else:
            assert abs(plain - expected) <= AGREE, (case, height, plain, expected)
            assert abs(together - expected) <= AGREE, (case, height, together, expected)


def turned_and_mirrored(case: dict) -> list[dict]:
    """The case swivelled half a turn either way and beyond 90° (a cylinder has no direction: the
    same body, its centre where the case has it), and with its centre across the work axis."""
    cx, cy, cz = case["centre"]
    return [{**case, "swivel": case["swivel"] + 180.0}, {**case, "swivel": case["swivel"] - 180.0},
            {**case, "swivel": 90.0 + abs(case["swivel"]) + 1.0}, {**case, "centre": (-cx, cy, cz)}]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("seed", [4, 5])
def test_a_hob_swivelled_beyond_90_degrees_or_across_the_axis_agrees_with_sampling(seed):
    """Adversary of issue 28: with cos A < 0 the band between the end faces came out empty, so a
    hob swivelled beyond ±90° met nothing; and the gap in X assumed the centre on the +X side."""
    rng = np.random.default_rng(seed + 100)
    for original in random_cases(seed, 12):
        for case in turned_and_mirrored(original):
            assert_agrees_with_sampling(case, heights_of(case, rng))


def test_the_reference_finds_a_cap_and_the_axis_inside():
    """The reference itself on two cases worked out by hand: a level hob (A = 0) R 40, L 100 at
    X 100, Y 80 (its end face at Y 30): at its centre height the nearest point is the cap's
    corner (60, 30), √(60² + 30²); and a hob whose centre is on the work axis: 0."""
    capped = {"radius": 40.0, "length": 100.0, "swivel": 0.0, "centre": (100.0, 80.0, 0.0)}
    assert reference(capped, 0.0) == pytest.approx(math.hypot(60.0, 30.0), abs=1e-9)
    through = {"radius": 40.0, "length": 100.0, "swivel": 25.0, "centre": (0.0, 0.0, 0.0)}
    assert reference(through, 10.0) == pytest.approx(0.0, abs=1e-9)


# --- whole programs: the batch's path (numpy, bounds first) against one gear's (plain floats) ----

MACHINE = "hobber-840d"
GEARS = [(42, Choices()), (45, Choices()), (43, Choices()), (47, Choices(feed_mode="conventional-climb", cuts=2)),
         (50, Choices()), (51, Choices()), (53, Choices(worm_feed="tangential")), (54, Choices())]
X_WORD = re.compile(r"X(-?\d+(?:\.\d+)?)")


def seeded_program(conn, monkeypatch, gear_id: int, choices: Choices):
    with monkeypatch.context() as patch:
        patch.setattr(verified_run, "prove", lambda *args, **kwargs: None)
        program = instantiate_gear(conn, gear_id, choices=choices)
    hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    hob = next(h for h in load_hobs(conn) if h.id == hob_id)
    return program, load_gear(conn, gear_id), hob, load_machine(conn, MACHINE)


def deeper(lines: list[str], by: float) -> list[str]:
    """Every move's X `by` mm nearer the work axis: cuts below the root, rapids into the blank."""
    return [X_WORD.sub(lambda m: f"X{float(m.group(1)) - by:.3f}", line) if line.lstrip().startswith(("G0", "G1", "N"))
            else line for line in lines]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("gear_id, choices", GEARS, ids=[str(gear) for gear, _ in GEARS])
def test_the_batch_path_reports_what_the_plain_floats_report(conn, monkeypatch, gear_id, choices):
    """The same findings word for word (depths and heights to the micrometre), cuts and times, on
    the program as made and moved 1.5 mm and 12 mm nearer the axis (cuts below the root, rapids
    into the blank: contacts to find)."""
    program, gear, hob, machine = seeded_program(conn, monkeypatch, gear_id, choices)
    said = []
    for lines in (program.lines, deeper(program.lines, 1.5), deeper(program.lines, 12.0)):
        reports = []
        for sections in (10 ** 12, -1):      # every section in plain floats; every one with numpy
            monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
            reports.append(simulate_program(lines, gear, hob, machine, program.name).lines())
        assert reports[0] == reports[1]
        said += reports[0]
    assert any("below the intended root" in line for line in said)
    assert any(" mm into " in line for line in said)
