"""Programs the verifier tests write line by line (the preludes of each dialect a machine needs
before a cut) and what the verifier says of them: accepted, or refused with one line."""
from __future__ import annotations

import psycopg
import pytest

from engine.machines.records import load_machine
from engine.verifier import LimitError, verify_program

HOBBING = ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR", "; GEAR 42", "G90 G71 G94 G54",
           "G25 X50.000 Y-30.000 Z-25.000", "G26 X62.000 Y30.000 Z20.000", "WALIMON"]
LATHE_840D = ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR", "; DRAWING part.dxf", "G18 G71 G90 G40 DIAMON"]
LATHE_ISO = ["%", "O0001 (TEST)", "(DRAWING part.dxf)", "G21 G18 G40 G90"]
PRELUDES = {"hobber-840d": HOBBING, "lathe-840d": LATHE_840D, "lathe-iso": LATHE_ISO}
# What a cut needs (engine.verifier.machine_state): the table coupled and the hob
# turning (S246/19 = 12.9 r/min of C, below hobber-840d's 120); a tool with its offset, the
# spindle turning, the feed mode stated.
READY = {"hobber-840d": ["G0 Y0.000", "EGDEF(C,B,1)", 'EGON(C,"FINE",B,-1,19)', "M3 S246"],
         "lathe-840d": ["T1 D1", "G97 S500 M3", "G94 F100"],
         "lathe-iso": ["T0101", "G97 S500 M03", "G98 F100."]}
# A hobbing program ends with the coupling off and deleted (reference §A7).
ENDINGS = {"hobber-840d": ["EGOFS(C)", "EGDEL(C)", "M30"], "lathe-840d": ["M30"], "lathe-iso": ["M30", "%"]}


def program(machine: str, body: list[str], ready: bool = True) -> list[str]:
    """A whole program named TEST: the prelude, what a cut needs (if `ready`), the body, the end."""
    return PRELUDES[machine] + (READY[machine] if ready else []) + body + ENDINGS[machine]


def refusal(conn, machine: str, lines: list[str]) -> str:
    with pytest.raises(LimitError) as raised:
        verify_program(lines, load_machine(conn, machine), "TEST")
    message = str(raised.value)
    assert "\n" not in message and "\r" not in message and message.endswith("nothing stored")
    return message


def accepted(conn, machine: str, lines: list[str]) -> bool:
    verify_program(lines, load_machine(conn, machine), "TEST")
    return True


def programs(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM program").fetchone()[0]


def one_line_exit_1(result) -> str:
    assert result.exit_code == 1, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    return lines[0]


def with_line_replaced(lines: list[str], old: str, *new: str) -> list[str]:
    """The program with the line `old` replaced by `new` (none: left out)."""
    at = lines.index(old)
    return [*lines[:at], *new, *lines[at + 1:]]


def verifier_refusal(machine, lines: list[str], name: str) -> str:
    """The verifier's refusal of the program on the machine record: one line, nothing stored."""
    with pytest.raises(LimitError) as raised:
        verify_program(lines, machine, name)
    message = str(raised.value)
    assert "\n" not in message and message.endswith("nothing stored")
    return message
