"""No move of a turning operation may enter the part: drawn tool paths and paths edited in
SQL are checked against the profile, not trusted. (Thread passes cut below the drawn
profile by design and are not checked here; that no rapid runs through the blank or the
material the feeds left is engine.turning.material's check.)

A move is sampled along its length; a sample point inside the part region deeper than
GOUGE_TOLERANCE_MM (a finish pass runs on the profile itself) is a gouge. The edges are
indexed by Z, and a move that stays above the part's largest radius over its Z span is
passed without sampling, so a large drawing costs little.
"""
from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterator, Sequence

from ..errors import EngineError
from .moves import Move, Pass
from .region import Edge, distance_to_edge

GOUGE_TOLERANCE_MM = 0.01    # a finish move on the profile is not a gouge; its chords lie within 1 µm
SAMPLE_STEP_MM = 0.25        # along a move: far below any real collar or groove width
BUCKET_MM = 1.0              # Z width of one cell of the edge index


class PartIndex:
    """The part's edges by Z cell, with the largest radius of each cell."""

    def __init__(self, edges: Sequence[Edge]):
        self.edges = list(edges)
        self.cells: dict[int, list[Edge]] = defaultdict(list)
        self.top: dict[int, float] = defaultdict(lambda: -math.inf)
        for edge in edges:
            (z0, r0), (z1, r1) = edge
            for cell in range(_cell(min(z0, z1)), _cell(max(z0, z1)) + 1):
                self.cells[cell].append(edge)
                self.top[cell] = max(self.top[cell], r0, r1)

    def top_over(self, z_a: float, z_b: float) -> float:
        return max((self.top[cell] for cell in range(_cell(min(z_a, z_b)), _cell(max(z_a, z_b)) + 1)
                    if cell in self.top), default=-math.inf)

    def depth_inside(self, z: float, radius: float) -> float:
        """0 outside the part or within GOUGE_TOLERANCE_MM of its boundary, else how deep."""
        edges = self.cells.get(_cell(z), ())
        if not _inside(z, radius, edges):
            return 0.0
        # An edge within the tolerance reaches into the cells of z ± tolerance.
        near = [edge for cell in range(_cell(z - GOUGE_TOLERANCE_MM), _cell(z + GOUGE_TOLERANCE_MM) + 1)
                for edge in self.cells.get(cell, ())]
        if any(distance_to_edge((z, radius), edge) <= GOUGE_TOLERANCE_MM for edge in near):
            return 0.0
        return min(distance_to_edge((z, radius), edge) for edge in self.edges)   # once, for the message


def _cell(z: float) -> int:
    return math.floor(z / BUCKET_MM)


def _inside(z: float, radius: float, edges: Sequence[Edge]) -> bool:
    """Even-odd rule with a ray from the point towards +radius (the edges crossing Z)."""
    crossings = 0
    for (z0, r0), (z1, r1) in edges:
        if (z0 <= z < z1) or (z1 <= z < z0):
            if r0 + (z - z0) * (r1 - r0) / (z1 - z0) > radius:
                crossings += 1
    return crossings % 2 == 1


def check_no_gouge(passes: list[Pass], index: PartIndex, where: str) -> None:
    """EngineError naming the operation, the block and how deep it would cut into the part."""
    here = None
    for one in passes:
        for move in one:
            if here is not None:
                _check_move(here, move, index, where)
            here = (move.z, move.x / 2.0)


def _check_move(start: tuple[float, float], move: Move, index: PartIndex, where: str) -> None:
    end = (move.z, move.x / 2.0)
    lowest = min(start[1], end[1]) if move.kind in ("rapid", "feed") else -math.inf
    if lowest > index.top_over(start[0], end[0]) + GOUGE_TOLERANCE_MM:
        return
    for z, radius in move_points(start, move):
        depth = index.depth_inside(z, radius)
        if depth:
            word = "G0" if move.kind == "rapid" else {"feed": "G1", "cw": "G2", "ccw": "G3"}.get(move.kind, "G1")
            raise EngineError(f"{where}: the {word} move to X{move.x:.3f} Z{move.z:.3f} cuts {depth:.3f} mm into "
                              f"the part at Z{z:.3f} X{2 * radius:.3f}; correct the drawn tool path or the profile")


def move_points(start: tuple[float, float], move: Move) -> Iterator[tuple[float, float]]:
    """(z, radius) points along a move from `start`, SAMPLE_STEP_MM apart, its end included (arcs on the arc)."""
    if move.kind in ("cw", "ccw") and move.i is not None and move.k is not None:
        yield from _arc_samples(start, move)
        return
    (z0, r0), (z1, r1) = start, (move.z, move.x / 2.0)
    count = max(1, math.ceil(math.hypot(z1 - z0, r1 - r0) / SAMPLE_STEP_MM))
    for n in range(1, count + 1):
        yield z0 + (z1 - z0) * n / count, r0 + (r1 - r0) * n / count


def _arc_samples(start: tuple[float, float], move: Move) -> Iterator[tuple[float, float]]:
    assert move.i is not None and move.k is not None   # an arc move has its centre
    centre = (start[0] + move.k, start[1] + move.i)
    radius = math.dist(start, centre)
    begin = math.atan2(start[1] - centre[1], start[0] - centre[0])
    finish = math.atan2(move.x / 2.0 - centre[1], move.z - centre[0])
    sense = 1.0 if move.kind == "ccw" else -1.0
    turn = (sense * (finish - begin)) % (2 * math.pi)
    count = max(1, math.ceil(radius * turn / SAMPLE_STEP_MM))
    for n in range(1, count + 1):
        angle = begin + sense * turn * n / count
        yield centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle)
