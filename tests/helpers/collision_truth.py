"""The true depth of a hob in a solid of revolution, measured independently of the engine, and
the programs the collision adversaries build (tests/test_collision_adversary*.py): the hob's
surface (its tip cylinder's mantle and both end faces, swivelled by A about X, Y along its own
axis, reference §A6) sampled in the DIN frame, the grid refined around its deepest point down to
well under 1e-4 mm. Every sampled point is a point of the hob, so the sampled depth is a lower
bound of the true one."""
from __future__ import annotations

import math

import numpy as np
import pytest
from msgspec.structs import replace

from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from helpers.simulation_programs import LOAD, RAPID_RATE, Hand, program_minutes

ALLOWED = 0.002          # mm: the claim's depth (contact_records.COLLISION_TOLERANCE)
# both paths of the contacts: one gear's plain floats and a batch's numpy (contact.MATH_SECTIONS)
PATHS = pytest.mark.parametrize("sections", [10 ** 12, -1], ids=["plain floats", "numpy"])
# The adversaries' programs cut one pass at the §C roughing feeds (about 3 mm/rev): their feed marks,
# f_a²·sin α_n/(4·d_a0) ≈ 10 µm (§B6), are within the share of the helix form tolerance a grade-9
# gear allows, not the seeded grade 7's. The gears are read as grade 9 so the adversaries prove the
# collisions they are about; the feed marks have their own (tests/test_feed_marks.py).
COARSE_GRADE = 9


def seeded_records(conn) -> dict:
    """The seeded hobber-840d, the hobs by id and a reader of gears, from the test's connection."""
    return {"machine": load_machine(conn, "hobber-840d"), "hobs": {hob.id: hob for hob in load_hobs(conn)},
            "gear": lambda gear_id: replace(load_gear(conn, gear_id), quality_grade=COARSE_GRADE)}


def _frame(swivel_deg: float):
    """The hob's axis u = (0, cos A, sin A) and the two radial directions X and e = (0, −sin A, cos A)."""
    a = math.radians(swivel_deg)
    return (np.array([0.0, math.cos(a), math.sin(a)]), np.array([1.0, 0.0, 0.0]),
            np.array([0.0, -math.sin(a), math.cos(a)]))


def _surface(r0, length, swivel_deg, centre, patch, first, second):
    """Points of one patch of the hob's surface on the grid first × second (1-D arrays):
    patch 0 the mantle (t along the axis, φ), 1 and 2 the end faces at ∓L/2 (ρ, φ)."""
    u, x_axis, e = _frame(swivel_deg)
    one, two = first[:, None, None], second[None, :, None]
    ring = np.cos(two) * x_axis + np.sin(two) * e
    if patch == 0:
        points = centre + one * u + r0 * ring
    else:
        points = centre + (-1 if patch == 1 else 1) * length / 2 * u + one * ring
    return points.reshape(-1, 3)


def _depths(points, radius: float, z_low: float, z_high: float):
    """How far each point lies inside a cylinder of `radius` about the work axis between z_low and
    z_high (mm): the lesser of its radial and its axial depth; −inf outside the heights."""
    radial = radius - np.hypot(points[:, 0], points[:, 1])
    axial = np.minimum(points[:, 2] - z_low, z_high - points[:, 2])
    return np.where(axial >= 0.0, np.minimum(radial, axial), -np.inf)


def true_depth(r0, length, swivel_deg, position, radius, z_low, z_high) -> float:
    """The deepest a hob of tip radius r0 and length L (mm), swivelled by A (degrees), at machine
    position (X, Y, Z) (Y along its own axis: the centre is (X, Y·cos A, Z + Y·sin A)), lies
    inside the cylinder (radius, z_low..z_high): a coarse grid over each patch, then grids ten
    times finer around the deepest point, six times (the last spacing well under 1e-4 mm)."""
    x, y, z = position
    a = math.radians(swivel_deg)
    centre = np.array([x, y * math.cos(a), z + y * math.sin(a)])
    spans = [(-length / 2, length / 2), (0.0, r0), (0.0, r0)]
    best = -math.inf
    for patch, (low, high) in enumerate(spans):
        first, second = np.linspace(low, high, 601), np.linspace(0.0, 2 * math.pi, 601)
        for _ in range(7):
            depth = _depths(_surface(r0, length, swivel_deg, centre, patch, first, second), radius, z_low, z_high)
            at = int(np.argmax(depth))
            one, two = first[at // len(second)], second[at % len(second)]
            width_one, width_two = (first[1] - first[0]) * 10, (second[1] - second[0]) * 10
            first = np.linspace(max(low, one - width_one), min(high, one + width_one), 201)
            second = np.linspace(two - width_two, two + width_two, 201)
        best = max(best, float(depth[at]))
    return best


def after_coupling(spur: Hand, extra: list[str]) -> list[str]:
    """The hand's program with `extra` blocks after the coupling is deleted and the spindle
    stopped (a shift while coupled is refused on its own, §B15), before M21/M30; with its cycle
    time header (helpers: the seeded machine's rapid rate and load position)."""
    spur.header = None
    lines = spur.lines()
    at = lines.index("M5") + 1
    body = lines[:at] + extra + lines[at:]
    return body[:2] + [f"; CYCLE TIME {program_minutes(body, RAPID_RATE, LOAD):.1f} MIN"] + body[2:]


def messages(report) -> list[str]:
    return [finding.message for finding in report.refusals]
