"""The parameters of an imported NC program (issue 17): each has a value and the addresses whose
numbers it binds. A number at another address that happens to equal the value is left alone:
the G71 allowance `U0.01` is not the feed `F0.010`, and doubling the feed must not double it.

A parameters file (JSON) gives each parameter in one of two forms:
* plain: `"feed": 0.01` binds the value at every address except the code addresses
  G, M, N, O, T (their numbers are codes, block numbers, program and tool numbers);
* bound: `"feed": {"value": 0.01, "addresses": ["F"]}` binds it only at F.

The class keeps the plain values (gear_class.import_params); instantiating it with other
values changes exactly the words bound at import."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import EngineError

# Addresses whose numbers are codes, not quantities: a plain parameter never binds them.
CODE_ADDRESSES = frozenset("GMNOT")


@dataclass(frozen=True)
class Binding:
    """One parameter: its value and the addresses (upper case) it binds; None = the plain form."""
    name: str
    value: object
    addresses: frozenset | None = None

    def binds(self, address: str | None) -> bool:
        """Whether a number written after `address` (None: no address) may become this parameter."""
        if self.addresses is None:
            return address is not None and address.upper() not in CODE_ADDRESSES
        return address is not None and address.upper() in self.addresses


def bindings(params: dict, source="parameters") -> dict[str, Binding]:
    """name → Binding of a parameters object in either form; a bound form that is not
    {"value": …, "addresses": [letters…]} is refused, naming the parameter."""
    return {name: _binding(name, given, source) for name, given in params.items()}


def values(params: dict, source="parameters") -> dict:
    """name → value of a parameters object in either form."""
    return {name: binding.value for name, binding in bindings(params, source).items()}


def _binding(name: str, given, source) -> Binding:
    if not isinstance(given, dict):
        return Binding(name, given)
    if set(given) != {"value", "addresses"}:
        raise EngineError(f"{source}: parameter {name!r} gives {sorted(given)}; write "
                          f"{{\"value\": 0.01, \"addresses\": [\"F\"]}} or a plain value")
    return Binding(name, given["value"], _addresses(name, given["addresses"], source))


def _addresses(name: str, addresses, source) -> frozenset:
    if not isinstance(addresses, list) or not addresses or not all(
            isinstance(address, str) and address.isalpha() and address.isascii() for address in addresses):
        raise EngineError(f"{source}: parameter {name!r}: addresses must be a non-empty list of address "
                          f"letters such as [\"F\"] or [\"X\", \"Z\"], not {addresses!r}")
    return frozenset(address.upper() for address in addresses)
