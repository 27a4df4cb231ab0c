"""Hobbing model of taper (conical) gears: the centre distance follows Z along the cone,
X(Z) = X(0) + Z·tan δ (reference §B12). Tip and root diameters are those at the top face
(Z = 0); a positive cone half-angle δ makes the gear smaller towards the bottom face."""
from __future__ import annotations

import math

from ..errors import EngineError
from ..gears.cutting_data import programmed_feed
from ..gears.models import register_model
from .cylindrical import RETRACT_CLEARANCE, CylindricalModel, Setup
from .envelope import clearance_to_cone
from .passes import Reach, pass_ends
from .root_contact import centre_on_root_cone

MAX_CONE_ANGLE = 15.0   # degrees: beyond a small taper the hob's generating geometry no longer holds
INFEED_CLEARANCE = 0.5  # mm between the hob envelope and the conical blank at the infeed
RUN_IN_STEP = 0.5       # mm: the run-in grows by this until the infeed clears, then is bisected
RUN_IN_TOLERANCE = 0.005
CONTACT_MARGIN = 0.5    # mm the contact point passes the face it leaves


@register_model("taper")
class TaperModel(CylindricalModel):
    class_parameters = frozenset({"cone_angle", "taper_slope"})
    cut_parameters = CylindricalModel.cut_parameters | {"feed_slant"}
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
        slope = math.tan(math.radians(gear.cone_angle))
        xs += [cut["cut_x"] + z * slope for cut in cuts for z in (cut["z_from"], cut["z_to"])]
        return xs, zs

    def cut_params(self, cut, gear, hob, cutting, setup) -> dict:
        """The infeed runs at the approach Z to X(z_from) on the cone line: where the cone
        line runs inward beyond the face entered (a positive cone entered from below, a
        negative one from above) the hob there sits deeper than the cut, so the run-in grows
        until the hob at that X clears the conical blank."""
        params = super().cut_params(cut, gear, hob, cutting, setup)
        run_in = self.run_in(gear, hob, setup, params["cut_x"], params["climb"])
        z_from, _ = pass_ends(Reach(run_in, setup.reach.overrun), 0.0, -gear.face_width, params["climb"])
        params["z_from"] = round(z_from, 3)
        # §B12: F of a G1 X Z is along the slant, so v_Z = F·cos δ keeps the axial feed; written at
        # or below it, and the cycle time counts the F written.
        params["feed_slant"] = programmed_feed(params["feed_axial"] / math.cos(math.radians(gear.cone_angle)))
        # The rapid stops short of the cone line at the approach Z, not of X(0).
        params["x_air"] = round(params["x_air"] + params["z_from"] * math.tan(math.radians(gear.cone_angle)), 3)
        return params

    def run_in(self, gear, hob, setup, cut_x: float, climb: bool) -> float:
        """The least run-in, at least the cylindrical one (§B7), at which the hob centred on
        the cone line at the approach Z clears the blank by INFEED_CLEARANCE."""
        slope = math.tan(math.radians(gear.cone_angle))
        blank = (gear.tip_diameter / 2, slope, gear.face_width)
        extent = hob.length      # half the hob plus the most it may be shifted, half its length
        face, outward = (0.0, 1) if climb else (-gear.face_width, -1)

        def clear(run_in: float) -> bool:
            z = face + outward * run_in
            centre = (cut_x + z * slope, z)
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
