"""What engine.simulation.hobbing.contact says about a move (shared with contact_arrays, the
batch's numpy path): what the hob is doing, the contact it finds, and the tolerance it counts
from."""
from __future__ import annotations

import msgspec

from .solids import Solid

TOLERANCE = 0.01      # mm: below the intended root, or into the blank it cuts, before it counts
# mm into a solid the hob must not touch (the fixture, the tailstock, a unit outside its cut)
# before it counts: the resolution the program is written in (X/Z with 3 decimals; an approach
# computed to touch may land that much nearer once rounded). A fixture is hardened steel: the
# depth tolerance of a cut (0.01 mm) let a crowned run-out pass 0.005 mm into a Ø20 fixture.
# It is held between the sampled heights and poses too (engine.simulation.hobbing.contact_bounds:
# bounds by convexity, the true deepest point searched where they reach it), so no allowance for
# the sampling is taken off it.
COLLISION_TOLERANCE = 0.002


class Motion(msgspec.Struct, frozen=True):
    """What the hob is doing on a move: which teeth it cuts (None: not an intended cut), whether
    the coupling is on with the spindle turning (its own gaps are free), in which coupling
    session, with the tailstock clamped or not, why it is not a cut (for the message), and
    whether the swivel A changes on it (the hob then turns as well as moves: not a translation,
    so contact_bounds' convexity does not hold and the sampled poses and heights are all that is
    checked)."""
    cutting_teeth: int | None
    coupled_running: bool
    session: int
    tailstock: bool
    reason: str
    swivelling: bool = False


class Contact(msgspec.Struct, frozen=True):
    """The hob's deepest reach into a solid during one move: a cut below the root, or a collision."""
    solid: Solid
    depth: float          # mm
    height: float         # DIN Z where it is deepest
    below_root: bool      # an intended cut below the root (else a collision)


def exact(solid: Solid, motion: Motion) -> bool:
    """Whether the solid's contact on the move is a collision held between the samples: not the
    intended cut, not a coupled move in the gaps its coupling cut (the session's reach is no
    convex solid), not a move that swivels the hob (not a translation: no convexity along it)."""
    cutting = motion.cutting_teeth is not None and solid.teeth == motion.cutting_teeth
    own_gaps = motion.coupled_running and solid.session == motion.session
    return not (cutting or own_gaps or motion.swivelling)


def contact_at(solid: Solid, depth: float, at: int, below_root: bool) -> Contact | None:
    """The deepest point (the first pose and lowest height of equal depths), or None (at -1)."""
    if at < 0:
        return None
    return Contact(solid, depth, solid.heights[at], below_root)
