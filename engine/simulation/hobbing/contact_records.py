"""What engine.simulation.hobbing.contact says about a move (shared with contact_arrays, the
batch's numpy path): what the hob is doing, the contact it finds, and the tolerance it counts
from."""
from __future__ import annotations

from dataclasses import dataclass

from .solids import Solid

TOLERANCE = 0.01      # mm: below the root, or into material, before it counts


@dataclass(frozen=True, slots=True)
class Motion:
    """What the hob is doing on a move: which teeth it cuts (None: not an intended cut), whether
    the coupling is on with the spindle turning (its own gaps are free), in which coupling
    session, with the tailstock clamped or not, and why it is not a cut (for the message)."""
    cutting_teeth: int | None
    coupled_running: bool
    session: int
    tailstock: bool
    reason: str


@dataclass(frozen=True, slots=True)
class Contact:
    """The hob's deepest reach into a solid during one move: a cut below the root, or a collision."""
    solid: Solid
    depth: float          # mm
    height: float         # DIN Z where it is deepest
    below_root: bool      # an intended cut below the root (else a collision)


def contact_at(solid: Solid, depth: float, at: int, below_root: bool) -> Contact | None:
    """The deepest point (the first pose and lowest height of equal depths), or None (at -1)."""
    if at < 0:
        return None
    return Contact(solid, depth, solid.heights[at], below_root)
