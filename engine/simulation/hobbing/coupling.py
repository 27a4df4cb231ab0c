"""The electronic gearbox as the simulation follows it (reference §A5, §A7): the signed terms of
`EGON(C,"FINE",B,<num>,<den>[,Z,<num>,<den>][,Y,<num>,<den>])`, which the verifier has read and
bounded (engine.verifier.statements keeps only their sizes), turned into the DIN frame,
and what the gear and hob need them to be:

* B → C: k_B = −h_hob·z0/z2, so the hob of z0 starts generates z0/|k_B| teeth;
* helical differential: k_Z = −h_gear·360·sin β/(π·m_n·z2) degrees of C per mm of Z (0 for spur);
* tangential worm wheels: k_Y = +360·cos γ/(π·m_n·z2) for both hob hands;
* swivel: A = h_hob·γ − h_gear·β, sin γ = z0·m_n/(d_a0 − 2.5·m_n).

A factor written with d decimals is right to half a unit of its last place (over its
denominator), plus FACTOR_TOLERANCE of its size."""
from __future__ import annotations

import math

import msgspec

from ...gears.records import Gear, Hob
from .frame import Senses

# The statements that start (or re-rate) the table's coupling and that end it, in each dialect:
# the 840D's EGON / EGOFS, EGDEL, Fanuc's G81 / G80 and the M series' G81.4 / G80.4.
COUPLING_ON = frozenset({"EGON", "G81", "G81.4"})
COUPLING_OFF = frozenset({"EGOFS", "EGDEL", "G80", "G80.4"})
ANGLE_TOLERANCE = 0.01       # degrees of swivel
FACTOR_TOLERANCE = 1e-6      # relative
HOB_DEDENDUM = 1.25          # d_m0 = d_a0 − 2·1.25·m_n (§B1)


class Coupling(msgspec.Struct, frozen=True):
    """One EGON (or Fanuc G81) in the DIN frame: k_B (C per B), and degrees of C per mm of Z and
    of Y, with the resolution each was written to; a Fanuc start also the words it gave them, so
    the findings name the words the program must change (engine.simulation.hobbing.fanuc_egb)."""
    numerator: int
    denominator: int
    k_b: float
    factors: dict            # "Z"/"Y" -> degrees of C per mm (DIN)
    resolution: dict         # "Z"/"Y" -> the rounding the program's digits allow
    program_factors: dict    # "B"/"Z"/"Y" -> the program's own value (table speed in program terms)
    command: str = "EGON"    # EGON, or the Fanuc start G81 / G81.4
    ratio_words: str = ""    # Fanuc: the threads and teeth words as written, "L-1 T19"
    helix_words: str = ""    # Fanuc: "Q3. P-15." (the helical compensation), "" where the block gives none

    def teeth(self, starts: int) -> float:
        return starts * self.denominator / abs(self.numerator)


def read_coupling(code: str, senses: Senses) -> Coupling:
    """`code` is an EGON the verifier has read: C, a mode, then (axis, numerator, denominator)."""
    arguments = code[code.index("(") + 1:code.rindex(")")].split(",")
    triples = arguments[2:]
    terms = {axis: (numerator, denominator) for axis, numerator, denominator
             in zip(triples[0::3], triples[1::3], triples[2::3])}
    numerator, denominator = (int(text) for text in terms.pop("B"))
    program = {"B": numerator / denominator}
    factors, resolution = {}, {}
    for axis, (top, bottom) in terms.items():
        program[axis] = float(top) / float(bottom)
        factors[axis] = program[axis] * senses.factor(axis)
        resolution[axis] = 0.5 * 10.0 ** -_decimals(top) / abs(float(bottom))
    return Coupling(numerator, denominator, program["B"] * senses.factor("B"), factors, resolution, program)


def _decimals(text: str) -> int:
    return len(text.partition(".")[2])


def hand_sign(hand: str | None) -> int:
    return -1 if hand == "L" else 1


def lead_angle(hob: Hob) -> float:
    """γ of the hob (§B1), degrees."""
    return math.degrees(math.asin(hob.starts * hob.module / (hob.tip_diameter - 2 * HOB_DEDENDUM * hob.module)))


def expected_swivel(gear: Gear, hob: Hob) -> float:
    return hand_sign(hob.hand) * lead_angle(hob) - hand_sign(gear.hand) * gear.helix_angle


def expected_k_b(hob: Hob, teeth: int) -> float:
    return -hand_sign(hob.hand) * hob.starts / teeth


def expected_k_z(gear: Gear, teeth: int) -> float:
    return -hand_sign(gear.hand) * 360 * math.sin(math.radians(gear.helix_angle)) / (math.pi * gear.module * teeth)


def expected_k_y(gear: Gear, hob: Hob, teeth: int) -> float:
    """k_Y = 360/(π·m_x0·z2) degrees of C per mm of Y (§B10): moved along its own axis by one axial
    pitch π·m_x0 = π·m_n0/cos γ0, the hob's thread stands as it stood one wheel tooth on. The hob's
    pitch, not the wheel's: the two are one pitch when the hob fits (engine.gears.hob_matching)."""
    return 360 * math.cos(math.radians(lead_angle(hob))) / (math.pi * hob.module * teeth)


def factor_agrees(found: float, wanted: float, resolution: float) -> bool:
    return abs(found - wanted) <= resolution + FACTOR_TOLERANCE * abs(wanted) + 1e-12


def helix_of(k_z: float, gear: Gear, teeth: int) -> tuple[float, str | None, float]:
    """(β, hand, lead in mm) that a differential k_Z (DIN) generates on `teeth` teeth of module m_n."""
    if k_z == 0:
        return 0.0, None, math.inf
    sine = min(1.0, abs(k_z) * math.pi * gear.module * teeth / 360)
    return math.degrees(math.asin(sine)), "R" if k_z < 0 else "L", 360 / abs(k_z)


def generated_teeth_problem(coupling: Coupling, hob: Hob, teeth_of_units: list[int]) -> str | None:
    teeth = coupling.teeth(hob.starts)
    if not any(abs(teeth - wanted) < 1e-9 for wanted in teeth_of_units):
        wanted = "/".join(str(t) for t in teeth_of_units)
        return (f"the coupling B {coupling.numerator}/{coupling.denominator} with a {hob.starts}-start hob generates "
                f"{teeth:g} teeth; the gear has {wanted}")
    return None


def coupling_problems(coupling: Coupling, gear: Gear, hob: Hob, teeth: int, worm_wheel: bool,
                      moving: frozenset) -> list[str]:
    """What is wrong with the coupling for a cut of the unit of `teeth` teeth that moves the
    axes `moving` (empty: nothing). A Z or Y term matters only where its axis moves in the cut."""
    problems = []
    wanted_b = expected_k_b(hob, teeth)
    if coupling.k_b * wanted_b < 0:
        problems.append(_hand_problem(coupling, hob, wanted_b))
    for axis, wanted in _wanted_factors(gear, hob, teeth, worm_wheel, moving).items():
        found = coupling.factors.get(axis, 0.0)
        if not factor_agrees(found, wanted, coupling.resolution.get(axis, 0.0)):
            problem = _factor_problem(axis, found, wanted, gear, teeth)
            problems.append(problem if coupling.command == "EGON" or axis != "Z" else _fanuc_z(coupling, problem))
    return problems


def _hand_problem(coupling: Coupling, hob: Hob, wanted: float) -> str:
    """k_B's sign against the hob's hand: on a Fanuc program, the L word that gives it and the
    sign the reference gives L on this machine (fanuc-egb.md §F5)."""
    problem = (f"the table turns the wrong way for a {hand_name(hob.hand)} hob: k_B is {coupling.k_b:+.6g} in "
               f"the DIN frame, the reference needs {wanted:+.6g} (−h_hob·z0/z2)")
    if coupling.command == "EGON":
        return problem
    return (f"{problem}: {coupling.command} {coupling.ratio_words} turns it so; L = −h_hob·c_direction·b_direction·z0 "
            f"is L{-coupling.numerator} on this machine (fanuc-egb.md §F5)")


def _fanuc_z(coupling: Coupling, problem: str) -> str:
    """The Z term's finding in the words of a Fanuc start: its Q and P (the control's helical
    compensation), or their absence, and the rule that signs P (fanuc-egb.md §F5)."""
    given = (f"{coupling.command}'s helical compensation {coupling.helix_words}"
             if coupling.helix_words else f"{coupling.command} without Q and P (no helical compensation)")
    return (f"{problem.replace('(DIN) generates', f'(DIN) of {given} generates', 1)}; Q = m_n and "
            "P = −h_gear·c_direction·z_direction·egb_helix_sign·β (fanuc-egb.md §F5)")


def _wanted_factors(gear, hob, teeth, worm_wheel, moving) -> dict:
    """The Z term of a cylindrical gear's axial pass (a worm wheel is not fed along Z: its helix
    comes from the hob's lead) and the Y term of a worm wheel's tangential feed (a cylindrical
    gear is not fed along Y while coupled)."""
    wanted = {"Z": 0.0 if worm_wheel else expected_k_z(gear, teeth),
              "Y": expected_k_y(gear, hob, teeth) if worm_wheel else 0.0}
    return {axis: value for axis, value in wanted.items() if axis in moving}


def _factor_problem(axis: str, found: float, wanted: float, gear: Gear, teeth: int) -> str:
    if axis == "Z":
        beta, hand, lead = helix_of(found, gear, teeth)
        made = "no helix (spur)" if hand is None else f"a {hand_name(hand)} helix of β {beta:.3f}°, lead {lead:.1f} mm"
        return (f"the Z term {found:+.6f}°/mm (DIN) generates {made}; the gear needs {wanted:+.6f}°/mm "
                f"(−h_gear·360·sinβ/(π·m_n·z2), {hand_name(gear.hand) if gear.helix_angle else 'spur'})")
    return (f"the Y term {found:+.6f}°/mm (DIN) is not the {wanted:+.6f}°/mm the hob's feed along Y needs "
            "(+360·cos γ0/(π·m_n0·z2) = 360/(π·m_x0·z2), the hob's axial pitch; 0 where Y does not feed while coupled)")


def swivel_problem(swivel_din: float, gear: Gear, hob: Hob) -> str | None:
    wanted = expected_swivel(gear, hob)
    if abs(swivel_din - wanted) <= ANGLE_TOLERANCE:
        return None
    return (f"the swivel A is {swivel_din:+.3f}° in the DIN frame, the reference needs {wanted:+.3f}° "
            f"(h_hob·γ − h_gear·β, γ {lead_angle(hob):.3f}°): the hob's thread would not lie along the teeth")


def hand_name(hand: str | None) -> str:
    return {"R": "right-hand", "L": "left-hand"}.get(hand, "spur") if hand is not None else "spur"
