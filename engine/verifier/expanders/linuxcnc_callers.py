"""A LinuxCNC subroutine file as the screen that calls it runs it (docs/reference/linuxcnc-lathe.md
§7). A file that only defines `o<name> sub … o<name> endsub` runs nothing by itself; ngcgui and the
lathe macros of gmoccapy/axis run it by writing a program around it:

* ngcgui (`#<name> = #1 (=0.260 Material Diameter)`): the preamble file, the subroutine file,
  `o<name> call [v1][v2]…` with the values of its form, and `m2` (ngcgui's "expand subroutines"
  output is one such file); verified with the documented defaults `(=value …)`.
* the lathe macros (`; MACRODEFAULTS=1.0,500.0,…`): the call with the defaults of the
  MACRODEFAULTS line (True/False as 1/0), from where the tool stands (the macro reads #<_x> and
  #<_z>), so the caller states the units, the diameter mode and that start position first.
* gmoccapy's own lathe macros (configs/sim/gmoccapy/lathe_configs): one MDI line written by its
  Cycles tab, after the INI's startup code; the data are in linuxcnc_gmoccapy.py.

Nothing here evaluates anything: it writes text the expander then reads like any program."""
from __future__ import annotations

import re

from ..refusals import Refused

SUB = re.compile(r"\s*o<([^>]+)>\s*sub\b", re.IGNORECASE)
NGCGUI_FIELD = re.compile(r"\s*#<[^>]+>\s*=\s*#(\d+)\s*\(\s*=\s*([-+]?[\d.]+)", re.IGNORECASE)
MACRO_DEFAULTS = re.compile(r"\s*;\s*MACRODEFAULTS\s*=\s*(.*)", re.IGNORECASE)
TRUTH = {"true": "1", "false": "0"}


def subroutine_name(lines: list[str]) -> str:
    for line in lines:
        match = SUB.match(line)
        if match:
            return match.group(1).lower()
    raise Refused("no o<name> sub in the file: not a subroutine file")


def ngcgui_defaults(lines: list[str]) -> list[str]:
    """The positional values #1, #2 … as the form's `(=value …)` comments give them."""
    fields = {int(m.group(1)): m.group(2) for m in map(NGCGUI_FIELD.match, lines) if m}
    if not fields or sorted(fields) != list(range(1, len(fields) + 1)):
        raise Refused("the ngcgui fields #1 … do not all give a default (=value)")
    return [fields[n] for n in sorted(fields)]


def macro_defaults(lines: list[str]) -> list[str]:
    for line in lines:
        match = MACRO_DEFAULTS.match(line)
        if match:
            return [TRUTH.get(value.strip().lower(), value.strip()) for value in match.group(1).split(",")]
    raise Refused("no ; MACRODEFAULTS= line in the file")


def as_called(lines: list[str], values: list[str], before: list[str]) -> list[str]:
    """`before` (a preamble, the caller's modes and position), the file up to its endsub (what
    follows, such as a macro file's M2, is never run by a call), its call, m2."""
    call = f"o<{subroutine_name(lines)}> call " + "".join(f"[{value}]" for value in values)
    return with_call(lines, call, before)


def with_call(lines: list[str], call: str, before: list[str]) -> list[str]:
    """As `as_called`, with the call line as the screen writes it; it must call the file's sub."""
    name = subroutine_name(lines)
    if not re.match(rf"\s*o<{re.escape(name)}>\s*call\b", call, re.IGNORECASE):
        raise Refused(f"the call {call.strip()!r} does not call o<{name}>, the file's subroutine")
    end = re.compile(rf"\s*o<{re.escape(name)}>\s*endsub\b", re.IGNORECASE)
    last = next((n for n, line in enumerate(lines) if end.match(line)), None)
    if last is None:
        raise Refused(f"o<{name}> sub without its o<{name}> endsub")
    return [*before, *lines[:last + 1], call, "m2"]
