"""Hobbing model of crowned gears: the centre distance is largest at mid-face and falls by
Δa = C_β / sin α_n at both faces along a parabola, a(Z) = a_mid − Δa·(2(Z − Z_m)/b)²
(reference §B11). The template emits it as a polyline of G1 X Z segments; the model gives
the parameters: crown_depth Δa, z_mid, and per cut the faces in pass order and the centre
distance at each vertex, crown_x_0 (the face entered) … crown_x_24 (the face left): where the
hob's whole tip cylinder touches the crowned root (engine.hobbing.root_contact). The parabola
itself, r0 straight out from the root, cut the root r0·a'²/2 too deep where it slopes (0.11 mm
at the faces for C_β 0.2), more for a swivelled hob."""
from __future__ import annotations

import math
from functools import lru_cache

from ..errors import EngineError
from ..gears.models import register_model
from . import geometry
from .cylindrical import RAPID_SHORT_OF_CUT, CylindricalModel
from .passes import APPROACH_SAFETY
from .root_contact import centre_on_root

MAX_CROWNING = 0.2   # mm of flank crowning C_β; more is not crowning but a different tooth form
CROWN_SEGMENTS = 24  # the template's polyline: G1 X Z segments per cut
MAX_FACE_SLOPE = 0.5  # dX/dZ of the crowned root at the faces (26.6°); crowning is far flatter
VERTICES = tuple(f"crown_x_{k}" for k in range(CROWN_SEGMENTS + 1))


@register_model("crowned")
class CrownedModel(CylindricalModel):
    class_parameters = frozenset({"crowning", "crown_depth", "z_mid"})
    cut_parameters = CylindricalModel.cut_parameters | {"face_from", "face_to"} | set(VERTICES)
    cut_shape = "crowned"

    def class_params(self, gear, hob, setup, choices) -> dict:
        if not gear.crowning or not 0 < gear.crowning <= MAX_CROWNING:
            raise EngineError(f"gear {gear.id}: class crowned needs a crowning 0 < C_β ≤ {MAX_CROWNING:g} mm, "
                              f"got {gear.crowning}; set crowning or choose another class")
        face_slope = 4 * crown_depth(gear) / gear.face_width   # a'(Z) at the faces
        if face_slope > MAX_FACE_SLOPE:
            raise EngineError(f"gear {gear.id}: crowning {gear.crowning:g} mm "
                              f"on a face of {gear.face_width:g} mm slopes "
                              f"the root by {math.degrees(math.atan(face_slope)):.0f}° at the faces (at most "
                              f"{math.degrees(math.atan(MAX_FACE_SLOPE)):.0f}°: beyond it a 24-segment polyline no "
                              f"longer follows it); reduce the crowning or check the face width")
        return {"crowning": gear.crowning, "crown_depth": round(crown_depth(gear), 4),
                "z_mid": round(-gear.face_width / 2, 4)}

    def cut_params(self, cut, gear, hob, cutting, setup) -> dict:
        params = super().cut_params(cut, gear, hob, cutting, setup)
        top, bottom = 0.0, -gear.face_width
        ends = (top, bottom) if cut.climb else (bottom, top)
        params["face_from"], params["face_to"] = beyond_faces(gear, hob, *ends)
        # the pass starts no later and ends no earlier than the polyline (it never runs back)
        down = 1 if cut.climb else -1
        params["z_from"] = round(down * max(down * params["z_from"], down * params["face_from"]), 3)
        params["z_to"] = round(down * min(down * params["z_to"], down * params["face_to"]), 3)
        stock = params["cut_x"] - setup.full_depth     # the rough cut's finishing stock, 0 on the last
        for name, z in zip(VERTICES, vertex_heights(params["face_from"], params["face_to"])):
            params[name] = round(tangent_centre(gear, hob, setup.swivel, z) + stock, 3)
        # the infeed to the first vertex, deeper than the cut's X, happens clear of the blank (§B7)
        entered = top if cut.climb else bottom
        clear = entered + down * infeed_approach(gear, hob, setup.swivel, params[VERTICES[0]])
        params["z_from"] = round(down * max(down * params["z_from"], down * clear), 3)
        params["x_air"] = round(params[VERTICES[0]] + RAPID_SHORT_OF_CUT, 3)   # the infeed goes to the face
        return params

    def extents(self, gear, setup, cuts):
        xs, zs = super().extents(gear, setup, cuts)
        xs += [min(cut[name] for name in VERTICES) for cut in cuts]
        return xs, zs


def beyond_faces(gear, hob, face_from: float, face_to: float) -> tuple[float, float]:
    """Where the polyline starts and ends: beyond each face by the distance along Z between the
    hob centre and its contact with the sloping root there, r0·sin(atan a'), plus 1 mm. The
    hob touches the root that far inside the face, so a polyline ending at the face leaves the
    root's last millimetres uncut (0.1 mm of stock at the faces for C_β 0.2); beyond the faces
    the path follows the parabola continued, where there is no material."""
    slope = 4 * crown_depth(gear) / gear.face_width
    reach = hob.tip_diameter / 2 * slope / math.sqrt(1 + slope ** 2) + 1.0
    outward = 1 if face_from > face_to else -1
    return face_from + outward * reach, face_to - outward * reach


def infeed_approach(gear, hob, swivel: float, infeed_x: float) -> float:
    """Run-in E (§B7) for the depth the hob has at the infeed X, plus the safety."""
    depth = min(geometry.cut_depth(gear.tip_diameter, hob.tip_diameter, infeed_x), hob.tip_diameter / 2)
    return geometry.approach_length(max(depth, 0.0), hob.tip_diameter, gear.tip_diameter, swivel) + APPROACH_SAFETY


def vertex_heights(face_from: float, face_to: float) -> list[float]:
    return [face_from + (face_to - face_from) * k / CROWN_SEGMENTS for k in range(CROWN_SEGMENTS + 1)]


def tangent_centre(gear, hob, swivel: float, z: float) -> float:
    """X of the hob centre at height z (DIN) with its tip cylinder touching the crowned root
    r(z) = d_f2/2 − Δa·(2(z − z_m)/b)² (continued beyond the faces, where there is no material)."""
    return _tangent_centre(gear.root_diameter / 2, crown_depth(gear), gear.face_width,
                           hob.tip_diameter / 2, hob.length, swivel, z)


@lru_cache(maxsize=4096)   # a job's two cuts, and a batch's like gears, meet the same heights
def _tangent_centre(root_radius, depth, face_width, hob_radius, hob_length, swivel, z) -> float:
    half_b, z_mid = face_width / 2, -face_width / 2
    return centre_on_root(lambda heights: root_radius - depth * ((heights - z_mid) / half_b) ** 2,
                          z, hob_radius, hob_length, swivel)


def crown_depth(gear) -> float:
    """Radial Δa = C_β / sin α_n (design notes §9)."""
    return gear.crowning / math.sin(math.radians(gear.pressure_angle))
