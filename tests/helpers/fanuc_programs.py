"""An 840D hobbing program the seeded templates make, rewritten line by line in the Fanuc hobbing
form (issue 30; docs/reference/fanuc-egb.md §F1, §F5), so the simulation can be shown to prove
the same program in either dialect. Every value of the electronic gear box is computed here from
the reference and the records, never taken from the engine's code:

    T = z2,   L = σ·z0,   σ = −h_hob · c_direction · b_direction      (fanuc-egb.md §F5)

and, for a helical gear, Q = m_n, P = −h_gear·c_direction·z_direction·egb_helix_sign·β (§F5; a
record that does not state egb_helix_sign gets the literal reading of the control's formula, +1)."""
from __future__ import annotations

import re

PROGRAM_NUMBER = 1234     # O1234 on a record without program_number_base (the simulation refuses it there)


def program_number(gear, machine) -> int:
    """The gear's O number on the machine: program_number_base + gear id (fanuc-egb.md §F7)."""
    base = getattr(machine, "program_number_base", None)
    return PROGRAM_NUMBER if base is None else base + gear.id
DROPPED = (re.compile(r";\$PATH=.*"), re.compile(r"G2[56] .*"), re.compile(r"WALIMON"),
           re.compile(r"EGDEF\(.*\)"), re.compile(r"EGDEL\(.*\)"))
HEADER = re.compile(r"%_N_(\w+)_MPF")
DWELL = re.compile(r"G4 F(\d+\.\d+)")     # the 840D templates' `G4 F{dwell:.1f}`, seconds


def hand(h: str | None) -> int:
    return -1 if h == "L" else 1


def threads_word(hob, machine) -> int:
    """L = −h_hob·c_direction·b_direction·z0 (fanuc-egb.md §F5)."""
    return -hand(hob.hand) * machine.c_direction * machine.b_direction * hob.starts


def helix_sign(machine) -> int:
    """The record's egb_helix_sign; not stated: +1, the literal reading of §F4's formula."""
    return 1 if machine.egb_helix_sign is None else machine.egb_helix_sign


def helix_words(gear, machine) -> str:
    """` Q<m_n> P<±β>` for a helical gear (§F5), '' for a spur gear."""
    if not gear.helix_angle:
        return ""
    helix = -hand(gear.hand) * machine.c_direction * machine.z_direction * helix_sign(machine) * gear.helix_angle
    return f" Q{gear.module:g}{'' if '.' in f'{gear.module:g}' else '.'} P{helix:.3f}"


def g81(gear, hob, machine, teeth: int | None = None, threads: int | None = None, helix: str | None = None) -> str:
    """The G81 block for the gear and hob on `machine` (arguments: a mistake to write instead)."""
    teeth = gear.teeth if teeth is None else teeth
    threads = threads_word(hob, machine) if threads is None else threads
    return f"G81 T{teeth} L{threads}{helix_words(gear, machine) if helix is None else helix}"


def fanuc_program(lines: list[str], gear, hob, machine, **mistake) -> list[str]:
    """`lines` (an 840D hobbing program) as a Fanuc program: % and O line, (comments), G21 for
    G71, T<n> without D, A<a> for A=<a>, EGON → G81 T L [Q P], EGOFS → G80; the 840D-only
    lines (the path directive, the G25/G26 working area, WALIMON, EGDEF, EGDEL) left out; the
    forms the Fanuc templates write for the rest (fanuc-egb.md §F8): the dwell `G4 F<s>` as
    `G04 X<s>` (seconds, with its point), the exact stop `G60` as `G61` (Fanuc's G60 is
    single-direction positioning), `G64` as it is (cutting mode); M20/M21 (tailstock), the door
    M codes, M8/M9 and T<n> as they are, their comments in parentheses."""
    out = ["%"]
    for line in lines:
        if any(pattern.fullmatch(line.partition(";")[0].strip() or line) for pattern in DROPPED):
            continue
        out.append(_line(line, gear, hob, machine, mistake))
    return [*out, "%"]


def _line(line: str, gear, hob, machine, mistake: dict) -> str:
    header = HEADER.fullmatch(line)
    if header:
        return f"O{program_number(gear, machine)} ({header.group(1)})"
    code, _, comment = (part.strip() for part in line.partition(";"))
    if code.startswith("EGON("):
        code = g81(gear, hob, machine, **mistake)
    elif code.startswith("EGOFS("):
        code = "G80"
    elif (dwell := DWELL.fullmatch(code)) is not None:
        code = f"G04 X{dwell.group(1)}"
    elif code == "G60":
        code = "G61"
    else:
        code = code.replace("G71", "G21").replace("A=", "A")
        code = re.sub(r" D1\b", "", code)
        code = " ".join(sorted(code.split(), key=_g_first)) if code.startswith("G90") else code
    return " ".join(part for part in (code, f"({comment})" if comment else "") if part)


def _g_first(word: str) -> int:
    """G21 G90 G94: the units first, as Fanuc programs state them (the order is free)."""
    return int(word[1:]) if word.startswith("G") else 1000
