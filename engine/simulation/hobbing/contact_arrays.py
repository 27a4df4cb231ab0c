"""engine.simulation.hobbing.contact for a batch, with numpy: a move's poses near a solid and the
heights each one spans as arrays, every section's least distance at once
(engine.simulation.hobbing.envelope_arrays), and the same rules as contact's plain floats: the
intended cut recorded in the unit's reach (the least distance per height over the move's
poses), the deepest point below the root or inside the material, the first pose and lowest
height of equal depths. Imported after a process's first contact.MATH_SECTIONS sections."""
from __future__ import annotations

import math

import numpy as np

from .contact_bounds_arrays import exact_collision
from .contact_records import COLLISION_TOLERANCE, TOLERANCE, Contact, Motion, contact_at, exact
from .envelope import HobBody
from .envelope_arrays import SLACK, Sections
from .paths import AXES, pose_count
from .solids import Solid


def meet_all(solids: list[Solid], hob: HobBody, swivel: float, pieces: list, motion: Motion) -> list[Contact]:
    """contact.follow's contacts for the solids its bounding box kept."""
    x, y, z = _poses(pieces)
    a = math.radians(swivel)
    cx, cy, cz = x, y * math.cos(a), z + y * math.sin(a)
    found = (_meet(solid, hob, swivel, cx, cy, cz, motion) if not exact(solid, motion)
             else exact_collision(solid, hob, swivel, pieces, _heights(solid), _blank(solid)) for solid in solids)
    return [contact for contact in found if contact is not None]


def _poses(pieces: list) -> tuple:
    """paths.pieces_poses as arrays, the same values (the same shares i/(n − 1) of each piece)."""
    shares = [np.arange(count) / (count - 1) for count in (pose_count(a, b) for a, b in pieces)]
    return tuple(np.concatenate([a.get(axis, 0.0) + share * (b.get(axis, 0.0) - a.get(axis, 0.0))
                                 for (a, b), share in zip(pieces, shares)]) for axis in AXES)


def _meet(solid: Solid, hob: HobBody, swivel: float, cx, cy, cz, motion: Motion) -> Contact | None:
    """The poses within reach of the solid, each with the heights its extent spans (padded
    with inf distances to the widest), measured where a bound does not settle them."""
    near = _near_poses(solid, hob.extent(swivel), hob.radius, cx, cy, cz)
    if near is None:
        return None
    cx, cy, cz, first, last = near
    cutting = motion.cutting_teeth is not None and solid.teeth == motion.cutting_teeth
    limit = None if cutting else _open_below(solid, motion)
    if limit is not None and (cx - hob.radius >= limit[first.min():last.max()].max() + SLACK).all():
        return None   # every pose keeps out of the material in X alone: _collision finds nothing
    count = len(solid.heights)
    raw = first[:, None] + np.arange(int((last - first).max()))[None, :]
    valid, index = raw < last[:, None], np.minimum(raw, count - 1)
    sections = Sections(hob, swivel, cx, cz, _heights(solid)[index])
    if limit is None:
        radius = _least_per_height(sections, cy, raw, valid, count)
        return _cut(solid, motion, index, radius, _per_height_least(radius, raw, count))
    if sections.farther_than(cy, np.where(valid, limit[index], -np.inf)):
        return None   # no section can come into the material: _collision finds nothing
    return _collision(solid, motion, index, np.where(valid, sections.nearest(cy), np.inf), limit)


def _near_poses(solid: Solid, extent: float, radius: float, cx, cy, cz):
    """(cx, cy, cz, first, last) of the poses within reach of the solid (contact._spans' tests),
    the first three of shape (P, 1); None for none."""
    near = (cx - radius < solid.largest_radius + TOLERANCE) & (cz + extent >= solid.z_low) & \
           (cz - extent <= solid.z_high)
    if not near.any():
        return None
    heights = _heights(solid)
    first = np.searchsorted(heights, cz[near] - extent)
    last = np.searchsorted(heights, cz[near] + extent, side="right")
    keep = last > first
    if not keep.any():
        return None
    return cx[near][keep][:, None], cy[near][keep][:, None], cz[near][keep][:, None], first[keep], last[keep]


def _heights(solid: Solid):
    """The solid's heights as an array, made once per solid."""
    if solid.height_array is None:
        solid.height_array = np.asarray(solid.heights, float)
    return solid.height_array


def _blank(solid: Solid):
    """The solid's radius per height as an array, made once per solid."""
    if solid.radius_array is None:
        solid.radius_array = np.asarray(solid.radius, float)
    return solid.radius_array


def _least_per_height(sections: Sections, cy, raw, valid, count: int):
    """The sections' distances where one may be the least at its height over the move's poses,
    inf elsewhere. A cut needs no more (_cut: the reach per height is that least, the unit is
    entered and the root passed where it is, and no other section is the deepest). A section
    whose lower bound is above the least upper bound at its height (by SLACK) is farther than
    the least and left out (most are: the hob passes a height with most of its poses well above
    or below it)."""
    lower, upper = sections.bounds(cy)
    lower = np.where(valid, lower, np.inf)
    least_upper = _per_height_least(np.where(valid, upper, np.inf), raw, count)
    keep = valid & (lower <= least_upper[np.minimum(raw, count - 1)] + SLACK)
    radius = np.full(lower.shape, np.inf)
    radius[keep] = sections.nearest(cy, keep)
    return radius


def _per_height_least(values, raw, count: int):
    """The least of `values` (shape (P, W), inf where not valid) at each of `count` heights:
    raw[p, j] is the height of values[p, j], increasing along a row (past count − 1 where
    the row is padded), so each lands in a cell of its own in a table of P rows."""
    table = np.full((raw.shape[0], count + raw.shape[1]), np.inf)
    table[np.arange(raw.shape[0])[:, None], raw] = values
    return table[:, :count].min(axis=0)


def _open_below(solid: Solid, motion: Motion):
    """Per height, the distance (mm) below which a section would be a collision: inside the
    material by COLLISION_TOLERANCE, and in its own gaps (_collision) also nearer than the coupling cut."""
    limit = _blank(solid) - COLLISION_TOLERANCE
    if motion.coupled_running and solid.session == motion.session:
        limit = np.minimum(limit, np.asarray(solid.session_reach, float) - TOLERANCE)
    return limit


def _cut(solid: Solid, motion: Motion, index, radius, least) -> Contact | None:
    """contact._cut: the least distance per height over the poses (`least`) into both reaches."""
    solid.start_session(motion.session)
    assert solid.intended_root is not None   # a unit the hob cuts has its intended root
    blank, root = _blank(solid), np.asarray(solid.intended_root)
    if (least < blank - TOLERANCE).any():
        solid.cut_sessions.add(motion.session)
    for i in np.flatnonzero(np.isfinite(least)).tolist():
        found = float(least[i])
        solid.reach[i] = min(solid.reach[i], found)
        solid.session_reach[i] = min(solid.session_reach[i], found)
    below = root[index] - radius
    return _deepest(solid, index, below, below > TOLERANCE, True)


def _collision(solid: Solid, motion: Motion, index, radius, limit) -> Contact | None:
    """contact._collision: nearer than `limit` (_open_below: inside the material by the collision
    threshold, except in the gaps this coupling cut)."""
    return _deepest(solid, index, _blank(solid)[index] - radius, radius < limit[index], False)


def _deepest(solid: Solid, index, depth, hit, below_root: bool) -> Contact | None:
    """The deepest hit, the first pose and lowest height of equal depths (row-major argmax)."""
    if not hit.any():
        return None
    at = int(np.argmax(np.where(hit, depth, -np.inf)))
    return contact_at(solid, float(depth.flat[at]), int(index.flat[at]), below_root)
