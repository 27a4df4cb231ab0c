"""A seeded template's program set to the reference where the templates before issue 14 were
wrong (the swivel A, the EGON's B numerator and Z/Y factors in the machine's senses, reference
§A7; Y positioned before coupling), every value computed here from the reference and the
records. After the templates follow the reference this changes nothing; until then it lets the
simulation be tested on the programs the templates make."""
from __future__ import annotations

import re

from simulation_programs import hand, k_y, k_z, swivel

SWIVEL = re.compile(r"G0 A=(-?\d+\.\d+)")
EGON = re.compile(r'EGON\(C,"FINE",B,(-?\d+),(\d+)((?:,[YZ],-?[\d.]+,[\d.]+)*)\)')
TERM = re.compile(r",([YZ]),(-?[\d.]+),([\d.]+)")


def to_reference(lines: list[str], gear, hob, machine) -> list[str]:
    out = [_line(line, gear, hob, machine) for line in lines]
    if not any(line.startswith(("G0 Y", "G0 Y=R11")) for line in out):
        at = next(i for i, line in enumerate(out) if line.startswith("EGDEF"))
        out.insert(at, "G0 Y0.000")
    return out


def _line(line: str, gear, hob, machine) -> str:
    if SWIVEL.fullmatch(line):
        return f"G0 A={swivel(gear, hob) * machine.a_direction + 0:.3f}"
    match = EGON.fullmatch(line)
    if not match:
        return line
    teeth = int(match.group(2))
    numerator = -hand(hob.hand) * hob.starts * machine.c_direction * machine.b_direction
    terms = "".join(_term(axis, teeth, gear, hob, machine) for axis, _, _ in TERM.findall(match.group(3)))
    return f'EGON(C,"FINE",B,{numerator},{teeth}{terms})'


def _term(axis: str, teeth: int, gear, hob, machine) -> str:
    if axis == "Z":
        return f",Z,{k_z(gear, teeth) * machine.c_direction * machine.z_direction:.6f},1"
    return f",Y,{k_y(gear, hob, teeth) * machine.c_direction * machine.y_direction:.6f},1"
