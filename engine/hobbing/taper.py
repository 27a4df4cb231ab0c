"""Hobbing model of taper (conical) gears: the centre distance follows Z along the cone,
X(Z) = X(0) + Z·tan δ (reference §B12). Tip and root diameters are those at the top face
(Z = 0); a positive cone half-angle δ makes the gear smaller towards the bottom face."""
from __future__ import annotations

import math

from ..errors import EngineError
from .cylindrical import RETRACT_CLEARANCE, CylindricalModel, Setup

MAX_CONE_ANGLE = 15.0   # degrees: beyond a small taper the hob's generating geometry no longer holds


class TaperModel(CylindricalModel):
    class_parameters = frozenset({"cone_angle", "taper_slope"})
    cut_shape = "taper"

    def setup(self, gear, hob) -> Setup:
        if not gear.cone_angle or abs(gear.cone_angle) > MAX_CONE_ANGLE:
            raise EngineError(f"gear {gear.id}: class taper needs a cone angle 0 < |δ| ≤ {MAX_CONE_ANGLE:g}°, "
                              f"got {gear.cone_angle}; set cone_angle or choose another class")
        setup = super().setup(gear, hob)
        slope = math.tan(math.radians(gear.cone_angle))
        # The pass reaches the approach distance beyond either face, where the cone line lies
        # furthest out: retract beyond it.
        highest = setup.full_depth + (gear.face_width + setup.reach.approach) * abs(slope)
        return Setup(setup.lead, setup.swivel, setup.full_depth, setup.reach,
                     max(setup.x_retract, highest + RETRACT_CLEARANCE))

    def class_params(self, gear, hob, setup, choices) -> dict:
        """taper_slope = dX/dZ = tan δ, turned with Z on the machine (engine.hobbing.conventions)."""
        return {"cone_angle": gear.cone_angle, "taper_slope": round(math.tan(math.radians(gear.cone_angle)), 9)}

    def cut_params(self, cut, gear, hob, cutting, setup) -> dict:
        """The infeed stops short of the cone line at the approach Z, not of X(0)."""
        params = super().cut_params(cut, gear, hob, cutting, setup)
        params["x_air"] = round(params["x_air"] + params["z_from"] * math.tan(math.radians(gear.cone_angle)), 3)
        return params

    def extents(self, gear, setup, cuts):
        xs, zs = super().extents(gear, setup, cuts)
        slope = math.tan(math.radians(gear.cone_angle))
        xs += [cut["cut_x"] + z * slope for cut in cuts for z in (cut["z_from"], cut["z_to"])]
        return xs, zs
