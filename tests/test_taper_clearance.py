"""Taper gears (issue 14 item 5): the infeed `G1 X{taper_x_0}` (the pass's first vertex) at the approach Z
leaves the hob clear of the conical blank, for both cone signs, climb and conventional, one
cut and two, swivel included; the pass still carries the hob centre beyond both faces.

Computed here from the geometry, independently of the engine: the blank is the solid of
revolution of the trapezoid r ≤ d_a2/2 + Z·tan δ over Z −b…0 (tip diameter d_a2 at the top
face, shrinking by 2·tan δ per mm downward for δ > 0); the distance of a point from it is the
distance, in the meridian plane through the point, from (r, Z) to that trapezoid. Points on
the hob's tip cylinder and end discs (radius d_a0/2, length L, axis in the Y–Z plane at the
swivel η: spur η = γ, helical β ∓ γ by hands, reference §B1, §B2) are tested at the infeed.
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from helpers.hob_clearance import CUTTING, MACHINE, hob_surface, seeded_hobs
from helpers.nc_reader import read_program
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.gears.records import Gear, Hob
from engine.hobbing.choices import FEED_MODES, Choices
from engine.hobbing.taper import TaperModel
from engine.programs.instantiate import instantiate_gear

MARGIN = 0.25           # mm: the least clearance an infeed may leave (the engine keeps more)


# ------------------------------------------------------------------ geometry, test side

def swivel(gear_beta: float, gear_hand: str | None, hob: Hob) -> float:
    """|η| in radians: γ for spur, β − γ for the same hands, β + γ for opposite (§B1, §B2)."""
    gamma = math.asin(hob.starts * hob.module / (hob.tip_diameter - 2.5 * hob.module))
    beta = math.radians(gear_beta)
    if not gear_beta:
        return gamma
    return abs(beta - gamma) if gear_hand == hob.hand else beta + gamma


def distance_to_trapezoid(r: np.ndarray, z: np.ndarray, corners: list) -> np.ndarray:
    """Signed distance of meridian points (r, z) from a convex polygon (negative inside); r and z
    broadcast against each other (many hob positions at once). The nearest point of each edge is
    compared squared, one square root at the end (issue 28: a third of this test's time)."""
    squared, inside = None, np.ones(np.broadcast_shapes(np.shape(r), np.shape(z)), dtype=bool)
    for (ar, az), (br, bz) in zip(corners, corners[1:] + corners[:1]):
        dr, dz = br - ar, bz - az
        from_r, from_z = r - ar, z - az
        t = np.clip((from_r * dr + from_z * dz) / (dr * dr + dz * dz), 0, 1)
        edge = (from_r - t * dr) ** 2 + (from_z - t * dz) ** 2
        squared = edge if squared is None else np.minimum(squared, edge)
        inside &= (dr * from_z - dz * from_r) >= 0      # corners run counterclockwise in (r, z)
    least = np.sqrt(squared)
    return np.where(inside, -least, least)


def blank_corners(tip_diameter: float, cone_angle: float, face_width: float) -> list:
    bottom = tip_diameter / 2 - face_width * math.tan(math.radians(cone_angle))
    return [(0.0, 0.0), (0.0, -face_width), (bottom, -face_width), (tip_diameter / 2, 0.0)]


def hob_clearance(surface: np.ndarray, centre: tuple, corners: list) -> float:
    return clearance_along(surface, np.array([centre[0]]), np.array([centre[1]]), corners)


def clearance_along(surface: np.ndarray, xs: np.ndarray, zs: np.ndarray, corners: list) -> float:
    """The least clearance of the hob with its centre at each (xs[k], zs[k]) (xs or zs of one value:
    that value for every position), all positions in one array: a point's meridian radius depends
    on the centre's X only, its height on the centre's Z only.
    Only points that may be nearest are measured exactly (issue 28): the blank lies inside the box
    0 ≤ r ≤ its largest radius, −b ≤ z ≤ 0, so a point's distance from the box is a lower bound
    of its distance from the blank, and a point whose bound exceeds the exact distance of the
    point with the least bound cannot be the nearest (points inside the blank have bound 0)."""
    r = np.hypot(surface[:, 0] + np.asarray(xs, dtype=float)[:, None], surface[:, 1])
    z = surface[:, 2] + np.asarray(zs, dtype=float)[:, None]
    r_max, bottom = max(r_corner for r_corner, _ in corners), min(z_corner for _, z_corner in corners)
    bound = np.hypot(np.maximum(r - r_max, 0.0), np.maximum(z, 0.0) + np.maximum(bottom - z, 0.0)).ravel()
    r, z = (np.broadcast_to(both, np.broadcast_shapes(r.shape, z.shape)).ravel() for both in (r, z))
    first = int(np.argmin(bound))
    enough = distance_to_trapezoid(r[first], z[first], corners)
    near = bound <= enough
    return float(min(enough, np.min(distance_to_trapezoid(r[near], z[near], corners), initial=np.inf)))


@functools.lru_cache(maxsize=8)
def gear_frame_surface(radius: float, half_length: float, eta: float) -> np.ndarray:
    """hob_surface, made once for the infeeds and the retract of one job."""
    surface = hob_surface(radius, half_length, eta)
    surface.flags.writeable = False
    return surface


def infeed_clearance(gear: Gear, hob: Hob, cut: dict, x_retract: float) -> float:
    """The hob along the infeed at the approach Z: X from the retract position to the pass's first vertex."""
    surface = gear_frame_surface(hob.tip_diameter / 2, hob.length / 2, swivel(gear.helix_angle, gear.hand, hob))
    corners = blank_corners(gear.tip_diameter, gear.cone_angle, gear.face_width)
    xs = np.linspace(cut["taper_x_0"], x_retract, 4)
    return clearance_along(surface, xs, np.array([cut["z_from"]]), corners)


def check_cuts(gear: Gear, hob: Hob, params: dict, module_params: dict) -> float:
    least = math.inf
    for cut in module_params.values():
        if not cut.get("cut_on"):
            continue
        low, high = sorted((cut["z_from"], cut["z_to"]))
        assert low < -gear.face_width and high > 0, f"the pass {low}…{high} does not cross both faces"
        found = infeed_clearance(gear, hob, cut, params["x_retract"])
        assert found >= MARGIN, f"{cut['cut_name']}: the infeed at Z{cut['z_from']} is {found:.2f} mm from the blank"
        least = min(least, found)
    found = retract_clearance(gear, hob, module_params, params["x_retract"])
    assert found >= MARGIN, f"the rapid along Z at X{params['x_retract']} is {found:.2f} mm from the blank"
    return least


def retract_clearance(gear: Gear, hob: Hob, module_params: dict, x_retract: float) -> float:
    """Between cuts the hob rapids along Z at the retract X from one pass's end to the next
    pass's approach, past the whole face, the blank's large end included (the bottom face for δ < 0)."""
    surface = gear_frame_surface(hob.tip_diameter / 2, hob.length / 2, swivel(gear.helix_angle, gear.hand, hob))
    corners = blank_corners(gear.tip_diameter, gear.cone_angle, gear.face_width)
    zs = [z for cut in module_params.values() if cut.get("cut_on") for z in (cut["z_from"], cut["z_to"])]
    return clearance_along(surface, np.array([x_retract]), np.linspace(min(zs), max(zs), 60), corners)


# ------------------------------------------------------------------ every combination, on the model

COMBINATIONS = [(cone, mode, cuts) for cone in (6.5, -6.5) for mode in sorted(FEED_MODES) for cuts in (1, 2)]


def paper_gear(cone: float, helix: float = 0.0, hand: str | None = None) -> Gear:
    """Reference §D: m2, z19, d_a 42.5 (d_f 33.5), b 20, cone 6.5°."""
    return Gear(50, "taper", 2.0, 19, 20.0, helix, hand, 20.0, 42.5, 33.5, cone, None, None, None, None, None)


@pytest.mark.parametrize("cone, feed_mode, cuts", COMBINATIONS)
def test_every_infeed_clears_the_cone(cone, feed_mode, cuts):
    hob = next(h for h in seeded_hobs() if h.id == "H-M2-AA-R1")
    gear = paper_gear(cone)
    job = TaperModel().job(gear, "taper", hob, MACHINE, CUTTING, Choices(feed_mode=feed_mode, cuts=cuts))
    check_cuts(gear, hob, job.params, job.module_params)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("cone, feed_mode, cuts", COMBINATIONS)
def test_every_infeed_clears_the_cone_with_a_helical_swivel(cone, feed_mode, cuts):
    hob = next(h for h in seeded_hobs() if h.id == "H-M2-A-L1")
    gear = paper_gear(cone, 20.0, "R")
    job = TaperModel().job(gear, "taper", hob, MACHINE, CUTTING, Choices(feed_mode=feed_mode, cuts=cuts))
    check_cuts(gear, hob, job.params, job.module_params)


@st.composite
def taper_gears(draw):
    hob = draw(st.sampled_from(seeded_hobs()))
    teeth = draw(st.integers(8, 120))
    helix = draw(st.sampled_from([0.0, 0.0, 10.0, 20.0, 30.0]))
    hand = draw(st.sampled_from("RL")) if helix else None
    reference = hob.module * teeth / math.cos(math.radians(helix))
    tip = round(reference + 2 * hob.module * (1 + draw(st.floats(-0.3, 0.5))), 2)
    cone = draw(st.floats(0.5, 15.0)) * draw(st.sampled_from([1, -1]))
    width = round(draw(st.floats(4.0, 60.0)), 1)
    gear = Gear(9201, "taper", hob.module, teeth, 20.0, helix, hand, width, tip, round(tip - 4.5 * hob.module, 3),
                round(cone, 2), None, None, None, None, None)
    choices = Choices(cuts=draw(st.sampled_from([None, 1, 2])), feed_mode=draw(st.sampled_from(sorted(FEED_MODES))))
    return gear, hob, choices


@pytest.mark.slow
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(taper_gears())
def test_random_taper_gears_infeed_clear_of_the_blank(layout):
    gear, hob, choices = layout
    try:
        job = TaperModel().job(gear, "taper", hob, MACHINE, CUTTING, choices)
    except EngineError as refusal:
        assert "\n" not in str(refusal)
        return
    check_cuts(gear, hob, job.params, job.module_params)


# ------------------------------------------------------------------ the paper's gear 50, end to end

@pytest.mark.parametrize("cone, feed_mode", [(6.5, "conventional-climb"), (6.5, "conventional"), (-6.5, "climb")])
def test_the_papers_gear_infeeds_clear_of_its_cone_in_the_program(conn, cone, feed_mode):
    """Seeded gear 50 (the paper's: cone 6.5°, conventional-climb was 0.62 mm inside)."""
    conn.execute("UPDATE gear SET cone_angle = %s WHERE id = 50", (cone,))
    row = conn.execute("SELECT module, teeth, face_width, tip_diameter, root_diameter "
                       "FROM gear WHERE id = 50").fetchone()
    gear = Gear(50, "taper", float(row[0]), row[1], 20.0, 0.0, None, float(row[2]), float(row[3]), float(row[4]),
                cone, None, None, None, None, None)
    program = instantiate_gear(conn, 50, choices=Choices(feed_mode=feed_mode, cuts=2))
    hob = next(h for h in seeded_hobs() if h.id == program.lines[3].split()[2])
    surface = hob_surface(hob.tip_diameter / 2, hob.length / 2, swivel(0.0, None, hob))
    corners = blank_corners(gear.tip_diameter, cone, gear.face_width)
    nc = read_program("\n".join(program.lines))
    infeeds = [m for m in nc.moves_in("G1") if m.changed == {"X"}]
    assert len(infeeds) == 2
    for move in infeeds:
        found = hob_clearance(surface, (move.end["X"], move.end["Z"]), corners)
        assert found >= MARGIN, f"{nc.blocks[move.block].text}: {found:.2f} mm from the blank"


# ------------------------------------------------------------------ a deep tooth on a cone growing downward

def test_the_retract_clears_the_large_end_of_a_cone_growing_downward():
    """Found by the random reference test: m4, z96, β 8° R, b 56.9, δ −5.83° (the blank grows
    b·tan|δ| = 5.81 mm in radius to the bottom face), hob 2 starts d_a0 90. The retract X kept
    5 mm over the cut line, not over the tip cone: with a 9 mm tooth the rapid between the cuts
    ran the hob tip 1.8 mm inside the bottom face's tip radius (d_a2/2 + 5.81 = 203.70)."""
    hob = Hob("H-M4-R2", 4.0, 20.0, 2, 90.0, 140.0, "R", "AA", None, None, None, 7)
    gear = Gear(9412, "taper", 4.0, 96, 20.0, 8.0, "R", 56.9, 395.774, 377.774, -5.83, None, None, None, None, None)
    job = TaperModel().job(gear, "taper", hob, MACHINE, CUTTING, Choices(shift_per_part=2.5))
    check_cuts(gear, hob, job.params, job.module_params)
    large_end = 395.774 / 2 + 56.9 * math.tan(math.radians(5.83))
    assert job.params["x_retract"] - 45.0 > large_end + MARGIN
