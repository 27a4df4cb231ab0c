"""The facts the header comments of a hobbing program state, read word by word and held to the
gear and hob records (the templates' forms, seed_templates/classes/*.csv):

* `; GEAR <id> CLASS <class> m=<m_n> z=<z2> beta=<β>` — the gear record (and CLASS the class of
  the `; TEMPLATE <class> v<n>` line);
* `; HOB <id> z0=<starts> da0=<d_a0> hand=<L|R>` — the hob record (the id, the hand and the
  machine line are held in engine.simulation.hobbing.rules);
* `; UNIT <n> z=<z> b=<b> Z<top>` — the gear's unit n (unit 1 is the gear itself, at Z0);
* `; n0=<r/min> r/min table=<r/min> r/min cuts=<1|2> <feed mode>` — engine.simulation.hobbing.program_facts
  holds n0, cuts and the feed mode to the program's own S words and cuts; here the table speed
  n2 = n0·z0/z2 (§B4).

A word these lines carry that is not one of the facts above is refused: it would go unchecked
while a reader takes it as the program's claim (fail closed, as engine.simulation.hobbing.headers)."""
from __future__ import annotations

import re

from ...gears.records import Gear, Hob

GEAR_LINE = re.compile(r"; GEAR \S+(?: CLASS (\S+))?((?: \S+)*)")
HOB_LINE = re.compile(r"; HOB \S+((?: \S+)*)")
UNIT_LINE = re.compile(r"; UNIT ([0-9]+) z=(\S+) b=(\S+) Z(\S+)")
TEMPLATE_LINE = re.compile(r"; TEMPLATE (\S+) v[0-9]+")
N0_LINE = re.compile(r"; n0=([0-9]+) r/min table=([0-9]+(?:\.[0-9]+)?) r/min cuts=([0-9]+) (\S+)")
PRINTED = 1e-5          # relative: `{:g}` prints six significant digits
TABLE_DECIMALS = 3


def words(text: str) -> dict[str, str] | None:
    """`k=v k=v` as a dict; None when a word is not k=v."""
    pairs = [word.partition("=") for word in text.split()]
    if any(not equals or not key or not value for key, equals, value in pairs):
        return None
    return {key: value for key, _, value in pairs}


def number(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if value == value and abs(value) < 1e9 else None   # NaN and inf are no facts


def agrees(stated: str, wanted: float) -> bool:
    value = number(stated)
    return value is not None and abs(value - wanted) <= PRINTED * max(1.0, abs(wanted))


def held(stated: dict[str, str], wanted: dict[str, float], what: str) -> str | None:
    """The first stated fact that is not the record's, or a word that is no fact."""
    for key, value in stated.items():
        if key not in wanted:
            return (f"the header states {key}={value}, which is no fact the simulation holds to the records "
                    f"(it states {', '.join(wanted)}); remove it")
        if not agrees(value, wanted[key]):
            return f"the header states {key}={value}; the {what} has {key}={wanted[key]:g}"
    return None


def gear_line_problem(line: str, gear: Gear, template_class: str | None) -> str | None:
    match = GEAR_LINE.fullmatch(line)
    if match is None:
        return None
    stated_class, rest = match.groups()
    if stated_class is not None and gear.gear_class is not None and stated_class != gear.gear_class:
        return f"the header states CLASS {stated_class}; gear {gear.id} is of class {gear.gear_class} (gear record)"
    if stated_class is not None and template_class is not None and stated_class != template_class:
        return f"the header states CLASS {stated_class}; the program's TEMPLATE line is of class {template_class}"
    stated = words(rest)
    if stated is None:
        return "the GEAR line's facts are not `CLASS <class> m=<m_n> z=<z2> beta=<β>` words"
    return held(stated, {"m": gear.module, "z": gear.teeth, "beta": gear.helix_angle}, f"gear record {gear.id}")


def hob_line_problem(line: str, hob: Hob) -> str | None:
    match = HOB_LINE.fullmatch(line)
    if match is None:
        return None
    stated = words(match.group(1))
    if stated is None:
        return "the HOB line's facts are not `z0=<starts> da0=<d_a0> hand=<L|R>` words"
    stated.pop("hand", None)         # held with the id (engine.simulation.hobbing.rules)
    return held(stated, {"z0": hob.starts, "da0": hob.tip_diameter}, f"hob record {hob.id}")


def unit_line_problem(line: str, gear: Gear, z_sense: int = 1) -> str | None:
    """The unit's teeth, face width and top face Z (in the program's Z: the DIN value times the
    machine's z sense, reference §A7)."""
    match = UNIT_LINE.fullmatch(line)
    if match is None:
        return None
    unit, teeth, width, top = match.groups()
    units = {1: (gear.teeth, gear.face_width, 0.0)}
    units.update({u.unit: (u.teeth, u.face_width, u.z_top * z_sense) for u in gear.units})
    if int(unit) not in units:
        return f"the header states unit {unit}; gear {gear.id} has units {', '.join(map(str, sorted(units)))}"
    wanted = dict(zip(("z", "b", "Z"), units[int(unit)]))
    return held({"z": teeth, "b": width, "Z": top}, wanted, f"gear record {gear.id} (unit {unit})")


def table_problem(line: str, gear: Gear, hob: Hob) -> str | None:
    """table = n0·z0/z2 (§B4), printed to TABLE_DECIMALS."""
    match = N0_LINE.fullmatch(line)
    if match is None:
        return None
    n0, table = float(match.group(1)), float(match.group(2))
    wanted = n0 * hob.starts / gear.teeth
    if abs(table - wanted) <= 0.5 * 10 ** -TABLE_DECIMALS + 1e-9:
        return None
    return (f"the header states table={match.group(2)} r/min; n0·z0/z2 = {n0:g}·{hob.starts}/{gear.teeth} = "
            f"{wanted:.{TABLE_DECIMALS}f} r/min (§B4)")


def template_class(lines: list[str]) -> str | None:
    for line in lines:
        match = TEMPLATE_LINE.fullmatch(line)
        if match:
            return match.group(1)
    return None
