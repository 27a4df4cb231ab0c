"""What engine.simulation.hobbing.contact says about a move (shared with contact_arrays, the
batch's numpy path): what the hob is doing, the contact it finds, and the tolerance it counts
from."""
from __future__ import annotations

from dataclasses import dataclass

from .solids import HEIGHT_STEP, Solid

TOLERANCE = 0.01      # mm: below the intended root, or into the blank it cuts, before it counts
# mm into a solid the hob must not touch (the fixture, the tailstock, a unit outside its cut)
# before it counts: the resolution the program is written in (X/Z with 3 decimals; an approach
# computed to touch may land that much nearer once rounded). A fixture is hardened steel: the
# depth tolerance of a cut (0.01 mm) let a crowned run-out pass 0.005 mm into a Ø20 fixture.
COLLISION_TOLERANCE = 0.002


def collision_threshold(hob_radius: float) -> float:
    """The depth (mm) a solid's sampled heights may show before it counts as a collision: the
    heights lie HEIGHT_STEP apart, and between two of them the hob may come nearer than at
    either by up to step²/(8·r0) (the clearance is convex in height), so the threshold is that
    much below COLLISION_TOLERANCE: what passes is at most COLLISION_TOLERANCE deep anywhere."""
    return max(0.0, COLLISION_TOLERANCE - HEIGHT_STEP ** 2 / (8 * hob_radius))


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
