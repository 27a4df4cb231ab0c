"""The Fanuc electronic-gear-box blocks of hobbing (issue 30; Fanuc 15i/150i-MA operator's manual
§19.9.2 "command compatible with hobbing machine"): `G81 T<teeth> L<±threads> [Q<module>
P<helix angle>]` synchronises the table C to the hob spindle at |L|/T table turns per hob turn,
the sign of L giving the table's direction, and `G80` cancels it (the M-series form: G81.4 R… L…
Q… P… and G80.4). Such a block is the command alone: its words are its arguments, not the
dialect's addresses (T here is the tooth count, not a tool), so it is read here, before the
block reader would take T for a tool call.

T (or R) and L are whole counts without a decimal point. Q (the module) and P (the helix angle)
must carry one: without it the control reads them in its least increment, whose unit differs
between the manuals (Q in 0.00001 mm; P in 0.0001° in the 15i-MA operator's manual, 0.00001°
in the 15i-B connection manual: reference fanuc-egb.md §F1), so a whole number there has no unit
the verifier can know; with the point, Q2.5 is 2.5 mm and P15. is 15°, the form the reference
(§F1, §F7) has the engine write. They come as a pair (one alone is Fanuc alarm PS0594), Q within
the 0.1 … 25 mm the 15i-B connection manual gives, P within ±90°. Without Q and P the control
adds no helical differential; with them it turns C by Z·sin P·360/(π·T·Q) degrees for every Z
move after G81, rapid ones included (fanuc-egb.md §F4, §F7's decision), so the statement carries
that factor, |sin P|·360/(π·T·Q) degrees of C per mm of Z, and the walk bounds the table speed a
Z move adds with it as it does EGON's Z term."""
from __future__ import annotations

import math
import re
from typing import TYPE_CHECKING

from .numbers import plain_decimal, whole_number
from .refusals import Refused
from .statements import GearBox, Statement

if TYPE_CHECKING:
    from .grammar import Dialect, Synchronisation

CODE = re.compile(r"G0*(\d+(?:\.\d+)?)")
WORD = re.compile(r"([A-Z])(.*)")
COUNT_DIGITS = 4          # teeth at most 1000, threads at most 30: a longer number is no count
MODULE_MM = (0.1, 25.0)        # Q with its decimal point, mm (15i-B connection manual, fanuc-egb.md §F1)
HELIX_DEGREES = (-90.0, 90.0)  # P with its decimal point, degrees (°), signed by the gear's hand
AXIAL_FEED_AXIS = "Z"          # the axis whose travel drives the helical compensation (fanuc-egb.md §F2)


def read_synchronisation(dialect: Dialect, code: str) -> Statement | None:
    """The EGB command a block gives (a Statement named by its G code, with the ratio |L|/T when
    it starts or changes the synchronisation), or None for a block that gives none."""
    commands = {command.code: command for command in dialect.synchronisations}
    tokens = code.split()
    found = [commands[match.group(1)] for match in map(CODE.fullmatch, tokens)
             if match is not None and match.group(1) in commands]
    if not found:
        return None
    command = found[0]
    if len(found) > 1:
        raise Refused(f"{command.event} and {found[1].event} in one block: each is a block of its own")
    words = _words(command, [token for token in tokens if not _is_code(token, command)])
    if not command.on:
        return Statement(command.event)
    box = _gear_box(command, words)
    return Statement(command.event, ratio=abs(box.threads) / box.teeth, factors=_helical_factor(box), gear_box=box)


def _is_code(token: str, command: Synchronisation) -> bool:
    match = CODE.fullmatch(token)
    return match is not None and match.group(1) == command.code


def _words(command: Synchronisation, tokens: list[str]) -> dict[str, str]:
    """address -> text of each word, each of the command's own addresses once and nothing else."""
    allowed = [address for address in (command.teeth, command.threads, *command.paired) if address]
    words: dict[str, str] = {}
    for token in tokens:
        match = WORD.fullmatch(token)
        address = match.group(1) if match else ""
        if address not in allowed:
            holds = f"only {', '.join(allowed)}" if allowed else "nothing else"
            raise Refused(f"a {command.event} block holds {holds}, not {token}: it is the synchronisation "
                          "command alone")
        if address in words:
            raise Refused(f"{address} twice in one block")
        words[address] = match.group(2) if match else ""
    return words


def _gear_box(command: Synchronisation, words: dict[str, str]) -> GearBox:
    """The start's terms, each checked: the teeth and the signed threads (|threads|/teeth table
    turns per hob turn, the 840D's z0/z2, reference §A5), Q and P both or neither."""
    helical = _all_given(command, words)
    teeth = _count(command.event, command.teeth, words[command.teeth], command.teeth_range, signed=False)
    threads = _threads(command, words[command.threads])
    teeth_word, threads_word = (f"{address}{words[address]}" for address in (command.teeth, command.threads))
    if not helical:
        return GearBox(teeth, threads, None, None, teeth_word, threads_word)
    module_word, helix_word = command.paired
    module = _increment(command.event, module_word, words[module_word], module=True)
    helix = _increment(command.event, helix_word, words[helix_word], module=False)
    return GearBox(teeth, threads, module, helix, teeth_word, threads_word,
                   f"{module_word}{words[module_word]} {helix_word}{words[helix_word]}")


def _all_given(command: Synchronisation, words: dict[str, str]) -> bool:
    """Whether Q and P are given; Refused without the teeth or the threads, or with one of Q, P."""
    for address, what in ((command.teeth, "the gear's number of teeth"), (command.threads, "the hob's threads")):
        if address not in words:
            raise Refused(f"{command.event} without {address} ({what}): each {command.event} states its whole ratio "
                          f"{command.teeth} and {command.threads} (the control would keep or default the other)")
    given = [address for address in command.paired if address in words]
    if given and len(given) < len(command.paired):
        missing = next(address for address in command.paired if address not in words)
        raise Refused(f"{command.event} with {given[0]} but without {missing}: the module Q and the helix angle P "
                      "of the helical compensation come both or neither (Fanuc alarm PS0594)")
    return bool(given)


def _threads(command: Synchronisation, text: str) -> int:
    threads = _count(command.event, command.threads, text, command.threads_range, signed=True)
    if threads == 0:
        raise Refused(f"{command.event} {command.threads}0: a hob has at least one thread (the sign of "
                      f"{command.threads} gives the table's direction)")
    return threads


def _helical_factor(box: GearBox) -> tuple[tuple[str, float], ...]:
    """((Z, |degrees of C per mm of Z|),) of the helical compensation Q and P ask for (fanuc-egb.md
    §F4: Z·sin P·360/(π·T·Q) for metric input), or () without them. P0. gives a factor of 0: the
    compensation stated as none, which a later G81 may rely on (program.py)."""
    if box.module is None or box.helix is None:
        return ()
    return ((AXIAL_FEED_AXIS, abs(helical_compensation(box.module, box.helix, box.teeth))),)


def helical_compensation(module: float, helix: float, teeth: int) -> float:
    """Degrees of C per mm of Z the control adds for G81's Q (`module`, mm) and P (`helix`,
    degrees) on a gear of `teeth` (fanuc-egb.md §F4, metric input): sin P·360/(π·T·Q), signed by
    P; the sign the control turns it with is the machine record's (egb_helix_sign, §F5)."""
    return math.sin(math.radians(helix)) * 360.0 / (math.pi * teeth * module)


def _count(event: str, address: str, text: str, bounds: range, signed: bool) -> int:
    """A whole count within `bounds`, no decimal point (teeth unsigned, threads signed)."""
    _no_point(event, address, text)
    value = whole_number(address, text, COUNT_DIGITS)
    if not signed and text[0] in "+-":
        raise Refused(f"{event} {address}{text}: the number of teeth has no sign (the sign of the threads "
                      "gives the table's direction)")
    if value not in bounds:
        low, high = (-bounds[-1], bounds[-1]) if signed else (bounds[0], bounds[-1])
        span = f"{low:+d} … {high:+d}, not 0" if signed else f"{low} … {high}"
        raise Refused(f"{event} {address}{text} is outside {span}")
    return value


def _increment(event: str, address: str, text: str, module: bool) -> float:
    """Q (the pair's first: the module, mm) or P (the helix angle, degrees), each written with its
    decimal point, within the range the manual gives."""
    if "." not in text:
        raise Refused(f"{event} {address}{text} needs a decimal point: without one the control reads it in its "
                      "least increment, whose unit the Fanuc manuals give differently (reference fanuc-egb.md §F1)")
    value = plain_decimal(address, text)
    low, high = MODULE_MM if module else HELIX_DEGREES
    if not low <= value <= high:
        what, unit = ("the module Q", " mm") if module else ("the helix angle P", "°")
        raise Refused(f"{event} {address}{text}: {what} must be within {low:g} … {high:g}{unit}")
    return value


def _no_point(event: str, address: str, text: str) -> None:
    if "." in text:
        raise Refused(f"{event} {address}{text}: {address} is a whole count, without a decimal point")
