"""Tool moves of a turning job, in machine coordinates: Z along the axis (mm), X as a
diameter (mm), as a program states them. The template rows decide how each kind is
written (engine.templates.nc_path), so the dialects live in rows, not here."""
from __future__ import annotations

import msgspec

from ..templates.nc_path import MOVE_KINDS  # noqa: F401  (the kinds nc_path prints, each in its format)


class Move(msgspec.Struct, frozen=True):
    """One block's motion to (z, x). Arcs: radius and the centre relative to the start
    point (i radial, k axial, both mm, i as a radius). Thread: the lead per turn."""
    kind: str
    z: float
    x: float
    radius: float | None = None
    i: float | None = None
    k: float | None = None
    pitch: float | None = None


Pass = list[Move]   # one pass: its approach, its cut, its retract
