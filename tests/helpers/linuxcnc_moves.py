"""The plain motion lines the LinuxCNC expander makes of a short program (shared by the expander
and drilling tests): START, the body, M2, on the test lathe."""
from __future__ import annotations

from engine.verifier.expanders.linuxcnc import expand_linuxcnc
from helpers.linuxcnc_programs import LATHE

START = ["G18 G21 G7 G90 G94", "T1 M6", "G43", "G97 S500 M3"]


def moves(*body: str, start: list[str] = START) -> list[str]:
    """The plain motion lines of START + body + M2."""
    plain = expand_linuxcnc([*start, *body, "M2"], LATHE)
    return [line.text for line in plain if line.text.split()[0] in ("G0", "G1", "G2", "G3")]
