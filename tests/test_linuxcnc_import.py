"""A verified LinuxCNC lathe program through import-nc and instantiate --class (issue 27): the
turning macro as its screen runs it (tests/helpers/linuxcnc_programs.py) is imported as a class
with the start diameter bound, made again on the seeded LinuxCNC lathe with a new value, and
only the bound word changes, to exactly the value given; the verifier read the new program.
A value that takes the program past the machine is refused and nothing is stored.

The macro indents with tabs; a stored NC line holds no control character (issue 26), and how
import-nc treats a tab is i27-importnc's to settle, so the file imported here has its tabs
written as spaces (LinuxCNC ignores both alike: the program is the same)."""
from __future__ import annotations

import json

import pytest
from helpers.class_jobs import ok, refused, stored_program
from helpers.linuxcnc_programs import LATHE, MACRO_START, program_of, refusal

TURNING = "lathe_macros/turning.ngc"


def imported(run, tmp_path):
    lines = [line.expandtabs(4) for line in program_of(TURNING)]
    source = tmp_path / "turning_called.ngc"
    source.write_text("\n".join(lines) + "\n")
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"start_diameter": {"value": 1.2, "addresses": ["X"]}}))
    ok(run("import-nc", source, "--class", "lc_turning", "--params", params))
    return lines


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_verified_linuxcnc_program_made_with_a_new_value_changes_only_its_bound_word(run, tmp_path):
    lines = imported(run, tmp_path)
    assert refusal(lines) is None and MACRO_START in lines
    new = tmp_path / "new.json"
    # the file's one decimal (writing a value's own digits, not the file's decimals, is i27-importnc's
    # fix), and the bar the simulation proves the job against (test_linuxcnc_programs.BAR)
    new.write_text(json.dumps({"start_diameter": 1.3, "stock_diameter": 30.48, "stock_z_front": 0,
                               "stock_z_back": -100}))
    made = json.loads(ok(run("instantiate", "--class", "lc_turning", "--machine", "lathe-linuxcnc", "--draft",
                             "--params", new, "--json")).stdout)
    made_lines, _, unverified = stored_program(run.url, made["program_id"])
    changed = [(old, now) for old, now in zip(lines, made_lines) if old != now]
    assert len(made_lines) == len(lines) and not unverified
    assert changed == [(MACRO_START, MACRO_START.replace("x1.2", "x1.3"))]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_value_past_the_travel_is_refused_and_nothing_is_stored(run, tmp_path):
    imported(run, tmp_path)
    past = LATHE.x_max / 25.4 + 1          # inches (the preamble's G20): a diameter beyond the travel
    new = tmp_path / "past.json"
    new.write_text(json.dumps({"start_diameter": round(past, 1)}))
    message = refused(run("instantiate", "--class", "lc_turning", "--machine", "lathe-linuxcnc", "--draft",
                          "--params", new))
    assert "exceeds the travel of lathe-linuxcnc" in message and "nothing stored" in message
