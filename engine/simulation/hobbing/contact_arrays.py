"""engine.simulation.hobbing.contact for a batch, with numpy: a move's poses near a solid and the
heights each one spans as arrays, every section's least distance at once
(engine.simulation.hobbing.envelope_arrays), and the same rules as contact's plain floats: the
intended cut recorded in the unit's reach (the least distance per height over the move's
poses: engine.simulation.hobbing.least_arrays), the deepest point below the root or inside the
material, the first pose and lowest height of equal depths. Imported after a process's first
contact.MATH_SECTIONS sections."""
from __future__ import annotations

import math

import numpy as np

from .contact_bounds_arrays import exact_collision
from .contact_records import COLLISION_TOLERANCE, TOLERANCE, Contact, Motion, contact_at, exact
from .envelope import HobBody
from .envelope_arrays import SLACK, Sections
from .least_arrays import least_sections
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


def _poses(pieces: list):
    """paths.pieces_poses as arrays (rows X, Y, Z), the same values (the same shares i/(n − 1)
    of each piece)."""
    rows = [_piece_poses(a, b) for a, b in pieces]
    return rows[0] if len(rows) == 1 else np.concatenate(rows, axis=1)


def _piece_poses(a: dict, b: dict):
    """The poses of one piece (rows X, Y, Z, mm): its start plus each share of its travel."""
    count = pose_count(a, b)
    start = np.array([[a.get(axis, 0.0)] for axis in AXES])
    travel = np.array([[b.get(axis, 0.0) - a.get(axis, 0.0)] for axis in AXES])
    return start + (np.arange(count) / (count - 1)) * travel


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
    if limit is None:
        return _cut(solid, motion, *least_sections(hob, swivel, (cx, cy, cz), _heights(solid), raw, last))
    valid, index = raw < last[:, None], np.minimum(raw, count - 1)
    sections = Sections(hob, swivel, cx, cz, _heights(solid)[index])
    if sections.farther_than(cy, np.where(valid, limit[index], -np.inf)):
        return None   # no section can come into the material: _collision finds nothing
    return _collision(solid, motion, index, np.where(valid, sections.nearest(cy), np.inf), limit)


def _near_poses(solid: Solid, extent: float, radius: float, cx, cy, cz):
    """(cx, cy, cz, first, last) of the poses within reach of the solid (contact._spans' tests),
    the first three of shape (P, 1); None for none."""
    near = np.flatnonzero((cx - radius < solid.largest_radius + TOLERANCE) & (cz + extent >= solid.z_low) &
                          (cz - extent <= solid.z_high))
    if not near.size:
        return None
    heights, at = _heights(solid), cz[near]
    first = np.searchsorted(heights, at - extent)
    last = np.searchsorted(heights, at + extent, side="right")
    keep = last > first
    if not keep.all():
        if not keep.any():
            return None
        near, first, last = near[keep], first[keep], last[keep]
    return cx[near][:, None], cy[near][:, None], cz[near][:, None], first, last


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
    reach, session_reach = solid.reach, solid.session_reach
    at = np.flatnonzero(np.isfinite(least))
    for i, found in zip(at.tolist(), least[at].tolist()):
        if found < reach[i]:
            reach[i] = found
        if found < session_reach[i]:
            session_reach[i] = found
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
