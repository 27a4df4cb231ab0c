"""The DIN 66217 frame the simulation works in (reference §A7): X from the work axis toward the
hob, Z up along the work axis (the gear's top face at Z = 0, the blank below), Y = Z × X, and
A, B, C right-handed about X, Y, Z. A machine whose axis points or turns the other way says so
in its record (machine.<axis>_direction = −1); its program values are the DIN values times the
senses involved, so dividing by them (the same as multiplying, for ±1) gives the DIN value."""
from __future__ import annotations

import msgspec

from ...machines.records import Machine


class Senses(msgspec.Struct, frozen=True):
    """The machine's axis senses (+1 or −1 each) of A, B, C, Y and Z, from its record."""
    a: int
    b: int
    c: int
    y: int
    z: int

    @classmethod
    def of(cls, machine: Machine) -> Senses:
        return cls(*(1 if int(getattr(machine, f"{axis}_direction")) >= 0 else -1 for axis in "abcyz"))

    def position(self, axis: str, value: float) -> float:
        """A programmed X, Y or Z in the DIN frame (X has no sense of its own: it is the centre distance)."""
        return value * {"X": 1, "Y": self.y, "Z": self.z}[axis]

    def swivel(self, value: float) -> float:
        return value * self.a

    def factor(self, axis: str) -> int:
        """What a programmed EGON factor of `axis` (C per B, per mm of Z, per mm of Y) is multiplied by."""
        return self.c * {"B": self.b, "Z": self.z, "Y": self.y}[axis]
