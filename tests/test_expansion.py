"""The seam every real dialect's interpreter plugs into (engine.verifier.expansion, issue 27): a
dialect that names an expander is read as the plain lines it makes, a refusal names the line of
the program as written that the refused plain line came from, and a dialect whose expander is not
loaded is refused (fail closed), never read as written."""
from __future__ import annotations

import pytest
from msgspec.structs import replace

from engine.machines.records import Machine
from engine.simulation.hobbing.reading import plain_lines
from engine.simulation.hobbing.report import SimulationError
from engine.verifier import LimitError, grammar, verify_program
from engine.verifier.expansion import EXPANDERS, ExpansionRefused, PlainLine, register_expander

LATHE = Machine("seam-lathe", "lathe", "iso", 0.0, 200.0, 0.0, 0.0, -300.0, 50.0, 3000.0, None, None)
PROGRAM = ["%", "O0001 (TEST)", "CALL 2", "M30", "%"]
BODY = ["G21 G18 G40 G90", "T0101", "G97 S500 M03", "G98 F100.", "G0 X40. Z2."]


@register_expander("seam-test")
def _expand_calls(lines: list[str], machine: Machine) -> list[PlainLine]:
    """`CALL n` stands for BODY with X multiplied by n: a toy subprogram call."""
    plain = []
    for number, line in enumerate(lines, start=1):
        if line == "CALL 9":
            raise ExpansionRefused(number, line, "CALL 9 is not in the file")
        if not line.startswith("CALL "):
            plain.append(PlainLine(line, number, line))
            continue
        factor = int(line.split()[1])
        for text in BODY:
            plain.append(PlainLine(text.replace("X40.", f"X{40 * factor}."), number, line))
    return plain


@pytest.fixture
def seam_dialect(monkeypatch):
    dialect = replace(grammar.LATHE_ISO, name="ISO lathe (seam test)", expander="seam-test")
    monkeypatch.setitem(grammar.DIALECTS, ("lathe", "seam"), dialect)
    return replace(LATHE, dialect="seam")


def test_a_dialect_with_an_expander_is_read_as_its_plain_lines(seam_dialect):
    verify_program(PROGRAM, seam_dialect, "TEST")
    assert [line.text for line in plain_lines(grammar.dialect_for(seam_dialect), PROGRAM, seam_dialect, "T")][2:7] \
        == [line.replace("X40.", "X80.") for line in BODY]


def test_a_refused_plain_line_names_the_line_as_written(seam_dialect):
    travel = seam_dialect.x_max           # CALL 6 moves to X240, past the 200 mm travel
    assert 40 * 6 > travel
    with pytest.raises(LimitError) as raised:
        verify_program(["%", "O0001 (TEST)", "CALL 6", "M30", "%"], seam_dialect, "TEST")
    assert "line 3 'CALL 6'" in str(raised.value) and "X240" in str(raised.value)


def test_an_expander_refusal_names_the_line_and_the_construct(seam_dialect):
    with pytest.raises(LimitError, match=r"line 3 'CALL 9': CALL 9 is not in the file; nothing stored"):
        verify_program(["%", "O0001 (TEST)", "CALL 9", "M30", "%"], seam_dialect, "TEST")
    with pytest.raises(SimulationError, match=r"line 3.*CALL 9 is not in the file"):
        plain_lines(grammar.dialect_for(seam_dialect), ["%", "O0001 (TEST)", "CALL 9"], seam_dialect, "T")


def test_a_dialect_whose_expander_is_not_loaded_is_refused(monkeypatch):
    dialect = replace(grammar.LATHE_ISO, name="ISO lathe (no expander)", expander="never-registered")
    monkeypatch.setitem(grammar.DIALECTS, ("lathe", "unloaded"), dialect)
    assert "never-registered" not in EXPANDERS
    with pytest.raises(LimitError, match="expander is not loaded"):
        verify_program(["%", "O0001 (TEST)", *BODY, "M30", "%"], replace(LATHE, dialect="unloaded"), "TEST")


def test_two_expanders_under_one_name_are_refused():
    with pytest.raises(ValueError, match="two expanders"):
        register_expander("seam-test")(lambda lines, machine: [])
