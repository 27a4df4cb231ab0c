"""Checks an emitted lathe program against its machine before anything is stored or written:
X (a diameter) and Z within the travel, arcs included (their extremes, not only their end
points), 0 < S ≤ the spindle's maximum, 0 < F ≤ MAX_FEED, tools 1 … 99, and every address
value a plain decimal. The hobbing rules (working area G25/G26 and WALIMON) do not apply: on
an ISO lathe G25/G26 mean something else, and a lathe program has no working-area limits."""
from __future__ import annotations

import math
import re

from ..gears.records import Machine
from ..programs.nc_check import LimitError, outside_travel
from .names import MAX_TOOL

MAX_FEED = 20000.0     # mm/min: about a lathe's rapid traverse; a larger F is a unit slip or a typo
_COMMENTS = re.compile(r"\([^)]*\)|;.*$")
_ADDRESS = re.compile(r"(?<![A-Z_$])([A-Z]{1,2})\s*=?\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:E[-+]?\d+)?|[-+]?(?:NAN|INF))")
_PLAIN_DECIMAL = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")


def check_lathe_program(lines: list[str], machine: Machine, program_name: str = "program") -> None:
    position: dict[str, float] = {}
    for number, line in enumerate(lines, start=1):
        found = addresses(line)
        problem = line_problem(found, machine, position)
        if problem:
            raise LimitError(f"{program_name} line {number} {line.strip()!r}: {problem}; nothing stored")
        position.update((letter, float(text)) for letter, text in found if letter in ("X", "Z"))


def addresses(line: str) -> list[tuple[str, str]]:
    """(address, value as written) of a block, comments left out."""
    if line.startswith(("%", ";")):
        return []
    return _ADDRESS.findall(_COMMENTS.sub("", line.upper()))


def line_problem(found: list[tuple[str, str]], machine: Machine, position: dict) -> str | None:
    for letter, text in found:
        if not _PLAIN_DECIMAL.fullmatch(text):
            return f"{letter}{text} is not a plain decimal number (controls read no exponent); check the parameter"
    for letter, text in found:
        problem = word_problem(letter, text, machine)
        if problem:
            return problem
    values = {letter: float(text) for letter, text in found}
    codes = {float(text) for letter, text in found if letter == "G"}
    if codes & {2, 3} and "X" in position and "Z" in position:
        return arc_problem(position, values, 3 in codes, machine)
    return None


def word_problem(letter: str, text: str, machine: Machine) -> str | None:
    value = float(text)
    if letter == "G" and value == 91:
        return "incremental G91 moves cannot be verified; program absolute positions (G90)"
    if letter in "SF" and value <= 0:
        return f"{letter}{text} must be above 0"
    if letter == "S" and value > machine.spindle_max:
        return f"spindle speed S{text} exceeds {machine.name}'s {machine.spindle_max:g} r/min"
    if letter == "F" and value > MAX_FEED:
        return f"feed F{text} exceeds {MAX_FEED:g} (mm/min), more than a lathe's rapid traverse"
    if letter == "T":
        return tool_problem(text, machine.dialect)
    if letter == "D" and not (text.isdecimal() and int(text) <= MAX_TOOL):
        return f"tool offset D{text} is not 0 … {MAX_TOOL}"
    if letter in "XYZ":
        return travel_problem(letter, value, machine)
    return None


def tool_problem(text: str, dialect: str) -> str | None:
    if dialect == "iso":
        if len(text) == 4 and text.isdecimal() and int(text[:2]) >= 1:
            return None
        return f"T{text} is not T<tool><offset>, two digits each, tool 01 … {MAX_TOOL}"
    if text.isdecimal() and 1 <= int(text) <= MAX_TOOL:
        return None
    return f"tool T{text} is not 1 … {MAX_TOOL}"


def travel_problem(letter: str, value: float, machine: Machine, what: str = "") -> str | None:
    problem = outside_travel(letter, value, machine)
    return problem and what + problem


def arc_problem(position: dict, values: dict, ccw: bool, machine: Machine) -> str | None:
    """An arc G02/G03 with R (ISO) or CR= (840D), X a diameter: its bounding box within the travel."""
    radius = values.get("R", values.get("CR"))
    if radius is None:
        return None
    start = (position["Z"], position["X"] / 2.0)
    end = (values.get("Z", position["Z"]), values.get("X", position["X"]) / 2.0)
    points = arc_extremes(start, end, radius, ccw)
    for letter, extreme in (("Z", min(z for z, _ in points)), ("Z", max(z for z, _ in points)),
                            ("X", 2.0 * min(r for _, r in points)), ("X", 2.0 * max(r for _, r in points))):
        problem = travel_problem(letter, round(extreme, 6), machine, "the arc reaches ")
        if problem:
            return problem
    return None


def arc_extremes(start, end, radius: float, ccw: bool) -> list[tuple[float, float]]:
    """The end points and the quadrant points the arc passes, in (z, r). ccw is G03 with Z to the
    right and the radius up; R > 0 the arc up to 180°, R < 0 the longer one."""
    centre = arc_centre(start, end, radius, ccw)
    size = abs(radius)
    a0, a1 = (math.atan2(p[1] - centre[1], p[0] - centre[0]) for p in (start, end))
    sweep = (a1 - a0) % math.tau if ccw else (a0 - a1) % math.tau
    points = [start, end]
    for quadrant in range(4):
        angle = quadrant * math.pi / 2
        turned = (angle - a0) % math.tau if ccw else (a0 - angle) % math.tau
        if turned <= sweep:
            points.append((centre[0] + size * math.cos(angle), centre[1] + size * math.sin(angle)))
    return points


def arc_centre(start, end, radius: float, ccw: bool) -> tuple[float, float]:
    dz, dr = end[0] - start[0], end[1] - start[1]
    chord = math.hypot(dz, dr)
    if chord == 0:
        return start
    rise = math.sqrt(max(radius * radius - chord * chord / 4.0, 0.0))
    side = 1.0 if ccw == (radius > 0) else -1.0      # the centre lies left of a short ccw arc
    return ((start[0] + end[0]) / 2.0 - side * rise * dr / chord,
            (start[1] + end[1]) / 2.0 + side * rise * dz / chord)
