"""The material a turning job has not cut yet, in the (Z, radius) plane, and the rule that a
rapid (G0) runs through air only: a rapid into uncut material breaks the tool or the machine.

The blank. The stored stock (params.stock_diameter, stock_z_front, stock_z_back). Without a
stored diameter (a drawing with operation layers imported without --stock-diameter) nothing
says how large the blank is, so it is assumed as large as the job suggests (fail closed):
between stock_z_back and stock_z_front (the profile's Z extent, stretched to every Z a feed of
its FACE operations feed along X at: a facing cut at Z+1 says the blank stands in front of the part), of the larger
radius of the profile's largest + ASSUMED_BLANK_MARGIN_MM (the blank import-dxf assumes for a
profile-only drawing, STOCK_MARGIN on the diameter) and the largest radius a feed of the job cuts at.

What a feed removes (the chip of a turning cut). An outside turning tool's body stands
radially outside its tip, so wherever a feed takes the tip, the radial column above it is
occupied by the tool and is air afterwards: a longitudinal feed removes the material radially
outside its path, a radial feed (a plunge, a facing feed) only its own line and what lies
above it — the engine knows no tool width. So the material left at each Z is what lies below
the lowest point any feed reached at that Z (the part included: it is never cut).

A rapid may run where there is no material: outside the blank, above that height, or back up
the line a plunge just fed. One that runs more than AIR_TOLERANCE_MM through material is
refused, naming the operation, the move and the length of its way through the material.
"""
from __future__ import annotations

import math
from collections import defaultdict

import msgspec

from ..drawings.profile import merged_bounds
from ..errors import EngineError
from .defaults import STOCK_MARGIN
from .gouge import move_points
from .moves import Move, Pass
from .operations import JobGeometry

AIR_TOLERANCE_MM = 0.01        # a rapid touching the material within this is in the air (float noise)
ASSUMED_BLANK_MARGIN_MM = STOCK_MARGIN / 2.0   # radial: import-dxf's default blank over the profile
SAMPLE_STEP_MM = 0.05          # along a rapid, between the Zs where the material's height changes course
COINCIDENT_MM = 1e-6           # a rapid back along a plunge runs at the plunge's own Z
TURN_NUDGE_MM = 1e-4           # beside a turn of the height: past COINCIDENT_MM, well inside AIR_TOLERANCE_MM
BISECTIONS = 30                # an entry into the material found to 2⁻³⁰ of a sample step
BUCKET_MM = 1.0                # Z width of one cell of the cut index

Point = tuple[float, float]


class Blank(msgspec.Struct, frozen=True):
    """The material before the first cut: Z from z_back to z_front, radius 0 … radius."""
    z_front: float
    z_back: float
    radius: float
    assumed: bool


def job_blank(stock: tuple[float, float, float] | None, profile_extent: tuple[float, float, float],
              passes: dict[int, list[Pass]], kinds: dict[int, str] | None = None) -> Blank:
    """The stored stock (z_front, z_back, radius), else the blank assumed (see the module's docstring);
    profile_extent is (z_front, z_back, largest radius) of the profile."""
    if stock is not None:
        return Blank(*stock, assumed=False)
    z_front, z_back, top = profile_extent
    feeds = [move for found in passes.values() for one in found for move in one if move.kind != "rapid"]
    faced = _facing_zs(passes, kinds or {})
    return Blank(max([z_front, *faced]), min([z_back, *faced]),
                 max([top + ASSUMED_BLANK_MARGIN_MM, *(move.x / 2.0 for move in feeds)]), assumed=True)


def _facing_zs(passes: dict[int, list[Pass]], kinds: dict[int, str]) -> list[float]:
    """The Zs where a FACE operation feeds along X: the face it cuts stands there, so the blank does
    too. Other feeds say nothing about the blank's Z: an infeed or a run-in starts in the air in
    front of the part."""
    zs = []
    for one in (one for n, found in passes.items() if kinds.get(n) == "FACE" for one in found):
        for before, move in zip(one, one[1:]):
            if move.kind != "rapid" and move.z == before.z and move.x != before.x:
                zs.append(move.z)
    return zs


class Cut(msgspec.Struct, frozen=True):
    """One straight piece of a feed: the column above it is air."""
    start: Point
    end: Point

    def covers(self, z: float) -> bool:
        low, high = sorted((self.start[0], self.end[0]))
        return low - COINCIDENT_MM <= z <= high + COINCIDENT_MM

    def floor_at(self, z: float) -> float:
        (z0, r0), (z1, r1) = self.start, self.end
        if abs(z1 - z0) <= COINCIDENT_MM:
            return min(r0, r1)
        t = min(1.0, max(0.0, (z - z0) / (z1 - z0)))
        return r0 + t * (r1 - r0)


class Material:
    """The blank less what the feeds so far have removed: a height over Z. Indexed by Z cell: a
    level cut over a whole cell is kept as the cell's floor, any other cut in the cell's list."""

    def __init__(self, blank: Blank):
        self.blank = blank
        self.cells: dict[int, list[Cut]] = defaultdict(list)
        self.floors: dict[int, float] = {}

    def remove(self, start: Point, move: Move) -> None:
        """A feed from start: the column above each piece of its path is air from now on."""
        if move.kind in ("feed", "thread"):
            self._add(Cut(start, (move.z, move.x / 2.0)))
            return
        here = start
        for point in move_points(start, move):
            self._add(Cut(here, point))
            here = point

    def _add(self, cut: Cut) -> None:
        (z0, r0), (z1, r1) = cut.start, cut.end
        low, high = min(z0, z1) - COINCIDENT_MM, max(z0, z1) + COINCIDENT_MM
        for cell in range(_cell(low), _cell(high) + 1):
            if r0 == r1 and low <= cell * BUCKET_MM and (cell + 1) * BUCKET_MM <= high:
                self.floors[cell] = min(self.floors.get(cell, r0), r0)
            else:
                self.cells[cell].append(cut)

    def height(self, z: float) -> float:
        """The radius below which material is left at Z (0 beyond the blank's faces)."""
        if not self.blank.z_back < z < self.blank.z_front:
            return 0.0
        cell = _cell(z)
        floors = [cut.floor_at(z) for cut in self.cells.get(cell, ()) if cut.covers(z)]
        return min([self.blank.radius, self.floors.get(cell, math.inf), *floors])

    def holds(self, point: Point) -> bool:
        return point[1] < self.height(point[0])

    def length_inside(self, start: Point, end: Point) -> tuple[float, Point | None]:
        """(mm of the straight rapid start → end that runs through material, a point of its first
        stretch in it)."""
        if min(start[1], end[1]) >= self.blank.radius or max(start[0], end[0]) <= self.blank.z_back \
                or min(start[0], end[0]) >= self.blank.z_front:
            return 0.0, None
        if start[0] == end[0]:
            return self._radial_length_inside(start[0], *sorted((start[1], end[1])))
        along = _along(start, end)
        count = max(1, math.ceil(math.dist(start, end) / SAMPLE_STEP_MM))
        fractions = sorted({k / count for k in range(count + 1)} | self._turns(start, end))
        inside = [self.holds(along(t)) for t in fractions]
        stretches = [self._stretch(along, a, b, inside[k], inside[k + 1])
                     for k, (a, b) in enumerate(zip(fractions, fractions[1:])) if inside[k] or inside[k + 1]]
        if not stretches:
            return 0.0, None
        return sum(hi - lo for lo, hi in stretches) * math.dist(start, end), along(sum(stretches[0]) / 2.0)

    def _turns(self, start: Point, end: Point) -> set[float]:
        """Fractions of the rapid just either side of each Z where the material's height changes
        course (an end of a cut, a cell's edge, a face of the blank): a rib narrower than the
        sampling step stands between two such Zs, so it is sampled whatever its width."""
        (z0, _), (z1, _) = start, end
        if z0 == z1:
            return set()
        low, high = sorted((z0, z1))
        cells = range(_cell(low), _cell(high) + 1)
        edges = {self.blank.z_front, self.blank.z_back, *(cell * BUCKET_MM for cell in cells),
                 *(cut_end[0] for cell in cells for cut in self.cells.get(cell, ())
                   for cut_end in (cut.start, cut.end))}
        nudged = {edge + side * TURN_NUDGE_MM for edge in edges for side in (-1, 1)}
        return {(z - z0) / (z1 - z0) for z in nudged if low < z < high}

    def _radial_length_inside(self, z: float, low: float, high: float) -> tuple[float, Point | None]:
        """A rapid along X only: the material at its Z is one stretch, from the axis up to the height."""
        top = min(high, self.height(z))
        return (top - low, (z, (low + top) / 2.0)) if top > low else (0.0, None)

    def _stretch(self, along, a: float, b: float, a_inside: bool, b_inside: bool) -> tuple[float, float]:
        """The part of [a, b] (fractions of the rapid, one end inside) that lies in material."""
        if a_inside and b_inside:
            return a, b
        boundary = self._boundary(along, a, b, a_inside)
        return (a, boundary) if a_inside else (boundary, b)

    def _boundary(self, along, a: float, b: float, a_inside: bool) -> float:
        """The fraction between a and b where the rapid crosses the material's edge."""
        for _ in range(BISECTIONS):
            middle = (a + b) / 2.0
            if self.holds(along(middle)) == a_inside:
                a = middle
            else:
                b = middle
        return (a + b) / 2.0


def _along(start: Point, end: Point):
    return lambda t: (start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1]))


def _cell(z: float) -> int:
    return math.floor(z / BUCKET_MM)


def check_job_rapids(geometry: JobGeometry, params: dict, module_params: dict, passes: dict[int, list[Pass]]) -> None:
    """The one check of every turning job's rapids (model.planned_passes): import-dxf, and every
    program made again from a stored job."""
    z_back, z_front, _, top = merged_bounds(geometry.outline)
    kinds = {n: module_params[f"cutmotion:{n}"]["kind"] for n in passes}
    blank = job_blank(geometry.stock, (z_front, z_back, top), passes, kinds)
    check_rapids_in_air(blank, passes, kinds, (float(params["tool_change_z"]), geometry.tool_change_radius))


def check_rapids_in_air(blank: Blank, passes: dict[int, list[Pass]], kinds: dict[int, str],
                        tool_change: Point) -> None:
    """Runs the job's operations in program order from the tool-change point, each entered by the
    template's tool-change block (G00 to the point from where the one before ended), removing what
    each feed cuts; EngineError at the first rapid through material."""
    material, here = Material(blank), tool_change
    for n in sorted(passes):
        for move in [Move("rapid", tool_change[0], 2.0 * tool_change[1])] + [m for one in passes[n] for m in one]:
            end = (move.z, move.x / 2.0)
            if move.kind == "rapid":
                _check_rapid(material, here, end, move, f"operation {n} {kinds[n]}")
            else:
                material.remove(here, move)
            here = end


def _check_rapid(material: Material, start: Point, end: Point, move: Move, where: str) -> None:
    length, inside = material.length_inside(start, end)
    if length <= AIR_TOLERANCE_MM:
        return
    assert inside is not None   # the move runs through the material
    z = inside[0]
    raise EngineError(f"{where}: G00 X{move.x:.3f} Z{move.z:.3f} runs {length:.2f} mm through "
                      f"{_material_named(material, z)}Ø{round(2 * material.height(z), 3):g} at Z{round(z, 3):g}): "
                      "rough it first (a ROUGH layer before it), give the blank it starts from (--stock-diameter, "
                      "params.stock_diameter) or draw its approach outside the material")


def _material_named(material: Material, z: float) -> str:
    """What the rapid runs into, as the refusal names it (the opening of its bracket included)."""
    if material.height(z) < material.blank.radius:
        return "material no earlier feed removed ("
    return "uncut assumed blank (no params.stock_diameter: " if material.blank.assumed else "uncut blank ("
