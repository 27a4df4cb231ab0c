"""Hobbing model of taper (conical) gears: the centre distance follows Z along the cone,
about X(Z) = X(0) + Z·tan δ (reference §B12). Tip and root diameters are those at the top face
(Z = 0); a positive cone half-angle δ makes the gear smaller towards the bottom face.

The template emits the pass as a polyline of G1 X Z segments (issue 29), as crowned's: per cut
the centre distance at each vertex, taper_x_0 (face_from) … taper_x_24 (face_to), where the
hob's whole tip cylinder touches the root cone r(z) = d_f2/2 + z·tan δ
(engine.hobbing.root_contact), and G1 Z at a held X before and after it (pass_x). A swivelled
hob's tangent centre is not on a straight line: its points off the Y = 0 plane meet the cone
where √(r² − y²) grows faster than r, so the straight line through the top face's centre left
0.01–0.08 mm of stock (δ > 0) or cut the root (δ < 0) at the far face of a helical taper of
δ ≥ 8°."""
from __future__ import annotations

import math
from functools import lru_cache

from ..errors import EngineError
from ..gears.cutting_data import programmed_feed
from ..gears.models import register_model
from .cylindrical import RETRACT_CLEARANCE, CylindricalModel, Setup
from .envelope import clearance_to_cone
from .passes import Reach, pass_ends
from .root_contact import centre_on_root_cone, contact_on_root

MAX_CONE_ANGLE = 15.0   # degrees: beyond a small taper the hob's generating geometry no longer holds
INFEED_CLEARANCE = 0.5  # mm between the hob envelope and the conical blank at the infeed
RUN_IN_STEP = 0.5       # mm: the run-in grows by this until the infeed clears, then is bisected
RUN_IN_TOLERANCE = 0.005
CONTACT_MARGIN = 0.5    # mm the contact point passes the face it leaves
TAPER_SEGMENTS = 24     # the template's polyline: G1 X Z segments per pass
REACH_MARGIN = 1.0      # mm the polyline runs on beyond where the contact passes a face (as crowned's)
VERTICES = tuple(f"taper_x_{k}" for k in range(TAPER_SEGMENTS + 1))


@register_model("taper")
class TaperModel(CylindricalModel):
    class_parameters = frozenset({"cone_angle", "taper_slope"})
    cut_parameters = CylindricalModel.cut_parameters | {"feed_slant", "face_from", "face_to"} | set(VERTICES)
    cut_shape = "taper"

    def setup(self, gear, hob) -> Setup:
        if not gear.cone_angle or abs(gear.cone_angle) > MAX_CONE_ANGLE:
            raise EngineError(f"gear {gear.id}: class taper needs a cone angle 0 < |δ| ≤ {MAX_CONE_ANGLE:g}°, "
                              f"got {gear.cone_angle}; set cone_angle or choose another class")
        setup = super().setup(gear, hob)
        # The tip cylinder touches the root cone: (d_f2 + d_a0)/2 would cut it r0·(1/cos δ − 1)
        # too deep (0.23 mm on the paper's 6.5° gear), more off the Y = 0 plane when swivelled.
        full_depth, contact_dz = centre_on_root_cone(gear.root_diameter / 2, gear.cone_angle,
                                                     hob.tip_diameter / 2, hob.length, setup.swivel)
        # Tangent to the cone, the hob touches the root about r0·sin|δ| along Z from its centre
        # (further off for a swivelled hob): the run-out carries the centre that much further,
        # or the face it leaves keeps stock (0.1 mm at 10°, 0.5 mm at 15° on a climb cut).
        overrun = setup.reach.overrun + abs(contact_dz) + CONTACT_MARGIN
        setup = Setup(setup.lead, setup.swivel, full_depth, Reach(setup.reach.approach, overrun), setup.x_retract)
        slope = math.tan(math.radians(gear.cone_angle))
        # The pass reaches the approach or run-out distance beyond a face, where the cone line
        # lies furthest out: retract beyond it. (A run-in lengthened for the cone (run_in) lies
        # where the cone line runs inward, so it never reaches further out.)
        highest = setup.full_depth + (gear.face_width + max(setup.reach.approach, setup.reach.overrun)) * abs(slope)
        return Setup(setup.lead, setup.swivel, setup.full_depth, setup.reach,
                     max(setup.x_retract, highest + RETRACT_CLEARANCE, self.tip_clear(gear, hob)))

    def tip_clear(self, gear, hob) -> float:
        """The rapids between cuts run along Z at the retract X past the whole face: the hob tip
        clears the blank's large end (the bottom face for δ < 0: d_a2/2 + b·tan|δ|) by
        RETRACT_CLEARANCE, as on a cylindrical gear. No point of the hob lies nearer the work axis
        than X − d_a0/2, whatever its swivel or shift."""
        growth = max(0.0, -gear.face_width * math.tan(math.radians(gear.cone_angle)))
        return (gear.tip_diameter + hob.tip_diameter) / 2 + growth + RETRACT_CLEARANCE

    def class_params(self, gear, hob, setup, choices) -> dict:
        """taper_slope = dX/dZ = tan δ, turned with Z on the machine (engine.hobbing.conventions)."""
        return {"cone_angle": gear.cone_angle, "taper_slope": round(math.tan(math.radians(gear.cone_angle)), 9)}

    def extents(self, gear, setup, cuts):
        xs, zs = super().extents(gear, setup, cuts)
        xs += [cut[name] for cut in cuts for name in VERTICES]
        return xs, zs

    def cut_params(self, cut, gear, hob, cutting, setup) -> dict:
        """The infeed runs at the approach Z to the pass's X there: where the cone runs inward
        beyond the face entered (a positive cone entered from below, a negative one from above)
        the hob there may sit deeper than the cut, so the run-in grows until it clears the
        conical blank. The pass then runs along Z to face_from, along the polyline's vertices
        (each the tangent centre at its height plus the cut's finishing stock, 0 on the last
        cut) to face_to, and along Z to the run-out (pass_x)."""
        params = super().cut_params(cut, gear, hob, cutting, setup)
        stock = params["cut_x"] - setup.full_depth
        run_in = self.run_in(gear, hob, setup, stock, params["climb"])
        z_from, _ = pass_ends(Reach(run_in, setup.reach.overrun), 0.0, -gear.face_width, params["climb"])
        params["z_from"] = round(z_from, 3)
        params["face_from"], params["face_to"] = polyline_ends(gear, hob, setup.swivel, params["z_from"],
                                                               params["z_to"])
        for name, z in zip(VERTICES, vertex_heights(params["face_from"], params["face_to"])):
            params[name] = round(pass_x(gear, hob, setup.swivel, z) + stock, 3)
        params["feed_slant"] = slant_feed(params, gear.cone_angle)
        # The rapid stops short of the first vertex at the approach Z, not of X(0).
        params["x_air"] = round(params["x_air"] - params["cut_x"] + params[VERTICES[0]], 3)
        return params

    def run_in(self, gear, hob, setup, stock: float, climb: bool) -> float:
        """The least run-in, at least the cylindrical one (§B7), at which the hob centred on
        the cut's path at the approach Z clears the blank by INFEED_CLEARANCE."""
        blank = (gear.tip_diameter / 2, math.tan(math.radians(gear.cone_angle)), gear.face_width)
        extent = hob.length      # half the hob plus the most it may be shifted, half its length
        face, outward = (0.0, 1) if climb else (-gear.face_width, -1)

        def clear(run_in: float) -> bool:
            z = face + outward * run_in
            centre = (pass_x(gear, hob, setup.swivel, z) + stock, z)
            return clearance_to_cone(hob.tip_diameter / 2, extent, setup.swivel, centre, blank) >= INFEED_CLEARANCE

        short = long = setup.reach.approach
        while not clear(long):
            short, long = long, long + RUN_IN_STEP
            if long > setup.reach.approach + hob.tip_diameter + gear.face_width:
                raise EngineError(f"gear {gear.id}: no run-in clears the cone of {gear.cone_angle:g}° for hob "
                                  f"{hob.id} (da0 {hob.tip_diameter:g}); use a smaller hob or another class")
        while long - short > RUN_IN_TOLERANCE:
            middle = (short + long) / 2
            short, long = (short, middle) if clear(middle) else (middle, long)
        return long


def vertex_heights(face_from: float, face_to: float) -> list[float]:
    """Z of the polyline's vertices, evenly from face_from to face_to (as the template)."""
    return [face_from + (face_to - face_from) * k / TAPER_SEGMENTS for k in range(TAPER_SEGMENTS + 1)]


def polyline_ends(gear, hob, swivel: float, z_from: float, z_to: float) -> tuple[float, float]:
    """(face_from, face_to): where the polyline starts and ends, the pass's ends or nearer."""
    top, bottom = 0.0, -gear.face_width
    entered, left = (top, bottom) if z_to < z_from else (bottom, top)
    return _polyline_end(gear, hob, swivel, entered, z_from), _polyline_end(gear, hob, swivel, left, z_to)


def _polyline_end(gear, hob, swivel: float, face: float, z_end: float) -> float:
    """Where the cone continued beyond `face` runs outward, the path follows it to the pass's
    end (a hob held at the face's X there would reach into the blank's edge). Where it runs
    inward, the path need follow it only until the hob's contact with the root has passed the
    face (contact_reach): beyond, X is held (pass_x), so the run-out dives no deeper towards an
    arbor or fixture under the gear's small end."""
    beyond = 1 if z_end > face else -1
    if beyond * math.tan(math.radians(gear.cone_angle)) > 0:
        return z_end
    return round(face + beyond * min(contact_reach(gear, hob, swivel, face), abs(z_end - face)), 3)


def contact_reach(gear, hob, swivel: float, face: float) -> float:
    """How far along Z beyond the face the centre must go for the hob's contact with the root
    cone to pass it (a swivelled hob touches the root off its centre's height), plus 1 mm."""
    return abs(_contact(*_key(gear, hob, swivel), face)[1]) + REACH_MARGIN


def pass_x(gear, hob, swivel: float, z: float) -> float:
    """X of the hob centre at height z on the last cut's pass: the tangent centre (path_x)
    within the faces and the contact reach beyond them, and beyond that the higher of it and
    the X at that reach. Never nearer the axis than the tangent centre, so the hob never
    reaches below the root cone; where the cone runs inward beyond a face it is held there."""
    low = -gear.face_width - contact_reach(gear, hob, swivel, -gear.face_width)
    high = contact_reach(gear, hob, swivel, 0.0)
    return max(path_x(gear, hob, swivel, z), path_x(gear, hob, swivel, min(max(z, low), high)))


def path_x(gear, hob, swivel: float, z: float) -> float:
    """X of the hob centre at height z (DIN) with its tip cylinder touching the root cone
    r(z) = d_f2/2 + z·tan δ (continued beyond the faces, where there is no material)."""
    return _contact(*_key(gear, hob, swivel), z)[0]


def _key(gear, hob, swivel: float) -> tuple:
    return (gear.root_diameter / 2, math.tan(math.radians(gear.cone_angle)), hob.tip_diameter / 2, hob.length,
            swivel)


@lru_cache(maxsize=4096)   # a job's cuts, its run-in search and a batch's like gears meet the same heights
def _contact(root_radius, slope, hob_radius, hob_length, swivel, z) -> tuple[float, float]:
    return contact_on_root(lambda heights: root_radius + heights * slope, z, hob_radius, hob_length, swivel)


def slant_feed(params: dict, cone_angle: float) -> float:
    """§B12: F of a G1 X Z is along the slant, so v_Z = F·cos θ keeps the axial feed: F = f_a/cos δ,
    lower where a segment (rounded to the micrometre) slopes less than the cone, so that no
    segment moves Z faster than feed_axial and no mark is wider than along the cone. Written at
    or below it; the cycle time counts the F written."""
    xs = [params[name] for name in VERTICES]
    run = (params["face_to"] - params["face_from"]) / TAPER_SEGMENTS
    slopes = [abs(b - a) / abs(run) for a, b in zip(xs, xs[1:])] if run else []
    slope = min([abs(math.tan(math.radians(cone_angle)))] + slopes)
    return programmed_feed(params["feed_axial"] * math.sqrt(1 + slope ** 2))
