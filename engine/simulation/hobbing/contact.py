"""Where a move's hob poses meet the solids (engine.simulation.hobbing.solids), and whether that is
the intended cut. Intended: a G1 with the table coupled and the hob spindle turning, in a
unit whose teeth the coupling generates, never below its intended root (less TOLERANCE). The
gaps such cuts leave are free to the hob while the same coupling lasts (a coupled retract out
of its own gaps), except on a rapid along Z (engine.simulation.hobbing.walk). Anything else that enters
material is a collision."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .envelope import HobBody, centres, nearest_radius
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
    solid: Solid
    depth: float          # mm
    height: float         # DIN Z where it is deepest
    below_root: bool      # an intended cut below the root (else a collision)


def follow(solids: list[Solid], hob: HobBody, swivel: float, x, y, z, motion: Motion) -> list[Contact]:
    """Every solid the poses (arrays x, y, z: machine positions, DIN) meet against the rules
    above; the intended cuts recorded in the units' reach."""
    cx, cy, cz = centres(np.asarray(x, float), np.asarray(y, float), np.asarray(z, float), swivel)
    contacts = []
    for solid in solids:
        if solid.clamped_only and not motion.tailstock:
            continue
        found = _meet(solid, hob, swivel, cx, cy, cz, motion)
        if found is not None:
            contacts.append(found)
    return contacts


def _meet(solid: Solid, hob: HobBody, swivel: float, cx, cy, cz, motion: Motion) -> Contact | None:
    extent = hob.extent(swivel)
    near = (cx - hob.radius < solid.largest_radius + TOLERANCE) & (cz + extent >= solid.z_low) & \
           (cz - extent <= solid.z_high)
    if not near.any():
        return None
    cx, cy, cz = cx[near][:, None], cy[near][:, None], cz[near][:, None]
    first = np.searchsorted(solid.heights, cz[:, 0] - extent)
    last = np.searchsorted(solid.heights, cz[:, 0] + extent, side="right")
    width = int((last - first).max())
    if width <= 0:
        return None
    index = first[:, None] + np.arange(width)[None, :]
    valid = index < last[:, None]
    index = np.minimum(index, len(solid.heights) - 1)
    radius = nearest_radius(hob, swivel, cx, cy, cz, solid.heights[index])
    radius = np.where(valid, radius, np.inf)
    if motion.cutting_teeth is not None and solid.teeth == motion.cutting_teeth:
        return _cut(solid, motion, index, radius)
    return _collision(solid, motion, index, radius)


def _cut(solid: Solid, motion: Motion, index, radius) -> Contact | None:
    solid.start_session(motion.session)
    finite = np.isfinite(radius)
    if (radius[finite] < solid.radius[index[finite]] - TOLERANCE).any():
        solid.cut_sessions.add(motion.session)
    np.minimum.at(solid.reach, index[finite], radius[finite])
    np.minimum.at(solid.session_reach, index[finite], radius[finite])
    assert solid.intended_root is not None   # a unit the hob cuts has its intended root
    below = solid.intended_root[index] - radius
    return _deepest(solid, index, below, below > TOLERANCE, True)


def _collision(solid: Solid, motion: Motion, index, radius) -> Contact | None:
    into = solid.radius[index] - radius
    hit = into > TOLERANCE
    if motion.coupled_running and solid.session == motion.session:
        hit &= radius < solid.session_reach[index] - TOLERANCE
    return _deepest(solid, index, into, hit, False)


def _deepest(solid: Solid, index, depth, hit, below_root: bool) -> Contact | None:
    if not hit.any():
        return None
    masked = np.where(hit, depth, -np.inf)
    at = np.unravel_index(int(np.argmax(masked)), masked.shape)
    return Contact(solid, float(masked[at]), float(solid.heights[index[at]]), below_root)
