"""Hobbing model of crowned gears: the centre distance is largest at mid-face and falls by
Δa = C_β / sin α_n at both faces along a parabola, a(Z) = a_mid − Δa·(2(Z − Z_m)/b)²
(reference §B11). The template emits it as a polyline of G1 X Z segments; the model gives
the parameters: crown_depth Δa, z_mid, and per cut the faces in pass order."""
from __future__ import annotations

import math

from ..errors import EngineError
from .cylindrical import CylindricalModel

MAX_CROWNING = 0.2   # mm of flank crowning C_β; more is not crowning but a different tooth form


class CrownedModel(CylindricalModel):
    class_parameters = frozenset({"crowning", "crown_depth", "z_mid"})
    cut_parameters = CylindricalModel.cut_parameters | {"face_from", "face_to"}
    cut_shape = "crowned"

    def class_params(self, gear, hob, setup, choices) -> dict:
        if not gear.crowning or not 0 < gear.crowning <= MAX_CROWNING:
            raise EngineError(f"gear {gear.id}: class crowned needs a crowning 0 < C_β ≤ {MAX_CROWNING:g} mm, "
                              f"got {gear.crowning}; set crowning or choose another class")
        return {"crowning": gear.crowning, "crown_depth": round(crown_depth(gear), 4),
                "z_mid": round(-gear.face_width / 2, 4)}

    def cut_params(self, cut, gear, hob, cutting, setup) -> dict:
        params = super().cut_params(cut, gear, hob, cutting, setup)
        top, bottom = 0.0, -gear.face_width
        params["face_from"], params["face_to"] = (top, bottom) if cut.climb else (bottom, top)
        params["x_air"] = round(params["x_air"] - crown_depth(gear), 3)   # the infeed goes to the face depth
        return params

    def extents(self, gear, setup, cuts):
        xs, zs = super().extents(gear, setup, cuts)
        xs += [cut["cut_x"] - crown_depth(gear) for cut in cuts]
        return xs, zs


def crown_depth(gear) -> float:
    """Radial Δa = C_β / sin α_n (design notes §9)."""
    return gear.crowning / math.sin(math.radians(gear.pressure_angle))
