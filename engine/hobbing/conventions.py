"""Signs of a hobbing job on a particular machine (reference §A7, design notes §7).

The models compute in the DIN 66217 frame: X from the work axis toward the hob, Z up along
the work axis (top face at Z = 0, the blank below), Y = Z × X, and A, B, C right-handed about
X, Y, Z. A machine whose axis points or turns the other way (machine.<axis>_direction = −1)
reads each value multiplied by the senses involved; this module is the one place that
turns DIN values into program values, so the templates print them as they are."""
from __future__ import annotations

import math

from ..machines.records import Machine

# Quantity -> the machine's direction fields whose product turns the DIN value into the
# program's: the table follows the hob (C per B), the helical differential (C per Z), the
# tangential feed (C per Y), the swivel (A), and the linear positions.
SENSES = {
    "swivel": ("a_direction",),
    "coupling_b": ("c_direction", "b_direction"),
    "differential": ("c_direction", "z_direction"),
    "tangential_factor": ("c_direction", "y_direction"),
    "z": ("z_direction",),
    "y": ("y_direction",),
}
# Job and cut parameters that are positions along Z or Y (a taper's slope dX/dZ turns with Z).
Z_POSITIONS = frozenset({"z_start", "z_end", "z_from", "z_to", "face_from", "face_to", "z_mid", "z_top",
                         "taper_slope"})
Y_POSITIONS = frozenset({"shift_y", "y_start", "y_end"})
# Lower/upper pairs: mirrored, the lower bound becomes the negated upper one.
Z_RANGES = (("z_lower", "z_upper"),)
Y_RANGES = (("y_lower", "y_upper"), ("shift_min", "shift_max"))


def hand_sign(hand: str | None) -> int:
    """h = +1 for a right hand, −1 for a left hand (a spur gear has none: its β is 0)."""
    return -1 if hand == "L" else 1


def sense(machine: Machine, quantity: str) -> int:
    """The product of the machine's senses that `quantity` depends on (+1 on a DIN machine)."""
    return math.prod(int(getattr(machine, field)) for field in SENSES[quantity])


def swivel(helix_angle: float, gear_hand: str | None, lead: float, hob_hand: str) -> float:
    """A = h_hob·γ − h_gear·β in the DIN frame (§A7): same hands |β − γ|, opposite |β + γ|."""
    return hand_sign(hob_hand) * lead - hand_sign(gear_hand) * helix_angle


def coupling_numerator(starts: int, hob_hand: str) -> int:
    """EGON numerator of B → C in the DIN frame: k_B = −h_hob·z0/z2 (§A7)."""
    return -hand_sign(hob_hand) * starts


def differential(module: float, teeth: int, helix_angle: float, gear_hand: str | None) -> float:
    """k_Z = −h_gear·360·sin β/(π·m_n·z2), degrees of C per mm of Z, DIN frame (§A7)."""
    return -hand_sign(gear_hand) * 360 * math.sin(math.radians(helix_angle)) / (math.pi * module * teeth)


def tangential_factor(module: float, teeth: int, lead: float) -> float:
    """k_Y = +360·cos γ0/(π·m_n0·z2) degrees of C per mm of Y, the hob's normal module m_n0 and lead γ0
    (its axial module m_x0 = m_n0/cos γ0: §B10), for either hob hand (§A7): the hob
    turned +360° equals a move of −lead (right hand) or +lead (left hand), and k_B already
    carries that hand, so the Y term does not."""
    return 360 * math.cos(math.radians(lead)) / (math.pi * module * teeth)


def on_machine(params: dict, machine: Machine) -> dict:
    """The parameters with every signed quantity, position and range in the machine's senses."""
    out = dict(params)
    for name in SENSES.keys() & out.keys():
        out[name] = _plain(out[name] * sense(machine, name))
    for names, axis in ((Z_POSITIONS, "z"), (Y_POSITIONS, "y")):
        for name in names & out.keys():
            out[name] = _plain(out[name] * sense(machine, axis))
    for ranges, axis in ((Z_RANGES, "z"), (Y_RANGES, "y")):
        for lower, upper in ranges:
            if lower in out and sense(machine, axis) < 0:
                out[lower], out[upper] = _plain(-out[upper]), _plain(-out[lower])
    return out


def _plain(value):
    """No −0: a program line `A=-0.000` reads as a sign error to an operator."""
    return value + 0 if value != 0 else type(value)(0)
