"""The parameters of an imported NC program (issue 17): each has a value and the addresses whose
numbers it binds. A number at another address that happens to equal the value is left alone:
the G71 allowance `U0.01` is not the feed `F0.010`, and doubling the feed must not double it.

A parameters file (JSON) gives each parameter in one of two forms:
* plain: `"feed": 0.01` binds the value at every address except the code addresses
  G, M, N, O, T (their numbers are codes, block numbers, program and tool numbers) and LinuxCNC's
  `$` (the spindle a word is for), and a number after no address (a cycle's argument `CYCLE95(…, 2.5)`,
  `R1=2.5`, `#<depth> = 2.5`, a column of an EMCO tape), but never a number that names something
  (engine.library.nc_references: `G71.1 Q100`'s contour, the 840D tool edge `D1`, `SETMS(1)`);
  a plain value may also be text or anything else the template reads (it binds no number);
* bound: `"feed": {"value": 0.01, "addresses": ["F"]}` binds it only at F (never a number after no
  address); its value must be a finite number, since binding is all it is for. At an address
  that names something it binds too (the user named it), except a block or program number,
  which is refused.

The class keeps the plain values (gear_class.import_params); instantiating it with other
values changes exactly the words bound at import."""
from __future__ import annotations

import math
from collections import Counter
from decimal import Decimal

import msgspec

from ..csv_reader import CellError, declare
from ..errors import EngineError

# Addresses whose numbers are codes, not quantities: a plain parameter never binds them.
CODE_ADDRESSES = frozenset("GMNOT$")
# Of those, the addresses whose numbers name a function (G1, M3, $0): a parameter's value equal to
# one is no quantity left behind, so the import does not warn about it.
FUNCTION_ADDRESSES = frozenset("GM$")


class Binding(msgspec.Struct, frozen=True):
    """One parameter: its value and the addresses (upper case) it binds; None = the plain form."""
    name: str
    value: object
    addresses: frozenset | None = None

    def binds(self, address: str | None) -> bool:
        """Whether a number written after `address` (None: no address) may become this parameter."""
        if self.addresses is None:
            return address is None or address.upper() not in CODE_ADDRESSES
        return address is not None and address.upper() in self.addresses

    def described(self) -> str:
        """The addresses as the import report names them: `F`, `X Z`, or the plain form's."""
        if self.addresses is None:
            return "every address but " + " ".join(sorted(CODE_ADDRESSES, key="GMNOT$".index))
        return " ".join(sorted(self.addresses))


def bindings(params: dict, source="parameters") -> dict[str, Binding]:
    """name → Binding of a parameters object in either form; a bound form that is not
    {"value": …, "addresses": [letters…]} is refused, naming the parameter."""
    return {name: _binding(name, given, source) for name, given in params.items()}


def values(params: dict, source="parameters") -> dict:
    """name → value of a parameters object in either form."""
    return {name: binding.value for name, binding in bindings(params, source).items()}


def _binding(name: str, given, source) -> Binding:
    if not isinstance(given, dict):
        return Binding(name, _finite(name, given, source))
    if set(given) != {"value", "addresses"}:
        raise EngineError(f"{source}: parameter {name!r} gives {sorted(given)}; write "
                          f"{{\"value\": 0.01, \"addresses\": [\"F\"]}} or a plain value")
    if not is_number(given["value"]):
        raise EngineError(f"{source}: parameter {name!r} has the value {given['value']!r}, which binds no word; "
                          f"a bound form's value is a number, such as {{\"value\": 0.01, \"addresses\": [\"F\"]}}")
    value = _finite(name, given["value"], source)
    return Binding(name, value, _addresses(name, given["addresses"], source))


def is_number(value) -> bool:
    """A value a word's number can equal: int, float or Decimal, not a truth value."""
    return isinstance(value, (int, float, Decimal)) and not isinstance(value, bool)


def _finite(name: str, value, source):
    """The value, refused when it is a number no program can write (NaN, infinity)."""
    if is_number(value) and not math.isfinite(value):
        raise EngineError(f"{source}: parameter {name!r} is {value!r}: NaN and infinity are no number a "
                          "program can write; give a finite value")
    return value


def _addresses(name: str, addresses, source) -> frozenset:
    if not isinstance(addresses, list) or not addresses or not all(
            isinstance(address, str) and address.isalpha() and address.isascii() for address in addresses):
        raise EngineError(f"{source}: parameter {name!r}: addresses must be a non-empty list of address "
                          f"letters such as [\"F\"] or [\"X\", \"Z\"], not {addresses!r}")
    return frozenset(address.upper() for address in addresses)


def parse_addresses(cell: str) -> list[str]:
    """The addresses a parameter binds, as a CSV cell writes them: `F`, `X Z`."""
    addresses = cell.split()
    if not all(address.isascii() and address.isalpha() for address in addresses):
        raise CellError("is not a list of address letters")
    return addresses


declare(parse_addresses, "address letters", "write the addresses it binds, such as F or X Z (none: every address "
                                            "but G M N O T $)")


NO_ADDRESS = "no address"   # the key of the numbers after no address (EMCO columns, cycle arguments)


def binding_report(bound: dict[str, Binding], words: Counter, lines: dict | None = None,
                   left: dict | None = None) -> list[dict]:
    """Each parameter in the order given, for the import report: the addresses it binds (None:
    the plain form's, every address but the codes), the words it bound (`words`: (name, address)
    → count) and how many at each address, with their line numbers (`lines`: (name, address) →
    lines), and per address the equal words it left as written (`left`, the same form: count and lines)."""
    lines, left = lines or {}, left or {}
    report = []
    for name, binding in bound.items():
        at = {address or NO_ADDRESS: count for (bound_name, address), count in sorted(
            words.items(), key=lambda item: item[0][1] or "") if bound_name == name}
        report.append({"parameter": name, "addresses": sorted(binding.addresses) if binding.addresses else None,
                       "binds": binding.described(), "words": sum(at.values()), "at": at,
                       "lines": _per_address(name, lines), "left_alone": {
                           address: {"words": len(numbers), "lines": numbers}
                           for address, numbers in _per_address(name, left).items()}})
    return report


def _per_address(name: str, lines: dict) -> dict[str, list[int]]:
    """address → the sorted line numbers of `name`'s entries in `lines` ((name, address) → lines)."""
    return {address or NO_ADDRESS: sorted(numbers) for (owner, address), numbers in sorted(
        lines.items(), key=lambda item: item[0][1] or "") if owner == name}


def refuse_blank_params(params: dict) -> None:
    """The blank of a class job (stock_diameter, stock_z_front, stock_z_back, mm) is what the turning
    simulation proves the program against, given at instantiate: bound at import it would also be a
    value of the program, and a new blank would rewrite every word that held its value (a G76 E0
    taper with stock_z_front 0)."""
    from ..simulation.turning import BLANK_PARAMS  # the simulation's names; not needed at start-up

    stated = [name for name in BLANK_PARAMS if name in params]
    if stated:
        raise EngineError(f"parameter {stated[0]} is the blank of a class job, not a value of the program: "
                          "leave it out of import-nc's params and give it to instantiate --params")
