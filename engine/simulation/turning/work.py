"""What a lathe program is proved against, read from the job's stored records (never from the
model that planned the passes): the finished part (params.profile, the drawing's half-profile in
(z, r)), the blank (params.stock_diameter, stock_z_front/back; without a stored diameter the
blank the importer assumes, design notes §8), the tool-change position (params.tool_change_x
as a diameter, tool_change_z), and per operation its kind, tool and offset, and for a THREAD
operation the region between its drawn crest and root lines. A class job (`engine instantiate
--class`: no drawing, so no params.profile and no operations) has only a blank: the one its
params state, or none, and then the simulation assumes one from the program
(engine.simulation.turning.undrawn)."""
from __future__ import annotations

import math

import msgspec
from shapely.affinity import scale
from shapely.geometry import Polygon, box
from shapely.geometry.base import BaseGeometry
from shapely.ops import unary_union

from ...errors import EngineError

# mm on the radius over the profile's largest: the blank import-dxf assumes for a drawing
# without a stored diameter (its default stock is the largest diameter + 2 mm).
ASSUMED_BLANK_MARGIN_MM = 1.0
ARC_SAGITTA_MM = 1e-4       # chord error of an arc drawn as a polyline: far inside the tolerances
MAX_ARC_PIECES = 4000
# The blank a job's params state (mm): a class job's only records (engine.simulation.turning.undrawn).
KINDS = ("ROUGH", "SLOT", "FINISH", "THREAD", "FACE", "PART")
FIX = "fix the job's params in SQL and instantiate it again"

Point = tuple[float, float]      # (z, r) mm


class Operation(msgspec.Struct, frozen=True):
    number: int
    kind: str
    tool: int | None
    offset: int | None


class TurningRecords(msgspec.Struct):
    """The job as stored, read for the simulation."""
    part: BaseGeometry
    stock: tuple[float, float, float] | None      # (z_front, z_back, radius) when stored
    z_front: float
    z_back: float
    top: float                                    # the profile's largest radius
    tool_change: tuple[float, float] | None       # (x diameter, z); None: no record (a class job)
    operations: dict[int, Operation] = {}
    threads: dict[int, BaseGeometry] = {}
    drawn: bool = True                            # False: a class job, proved without a drawing record

    def blank(self, feed_radius: float, facing_zs: list[float]) -> BaseGeometry:
        """The material before the first cut (both sides of the axis). Without a stored stock
        (fail closed, as the importer assumes it): the profile's Z extent stretched to every Z a
        FACE operation feeds along X at, and the larger of the profile's top + ASSUMED_BLANK_MARGIN_MM and the largest
        radius the program feeds at."""
        if self.stock is not None:
            z_front, z_back, radius = self.stock
            return box(z_back, -radius, z_front, radius)
        radius = max(self.top + ASSUMED_BLANK_MARGIN_MM, feed_radius)
        return box(min([self.z_back, *facing_zs]), -radius, max([self.z_front, *facing_zs]), radius)


def turning_records(params: dict, module_params: dict) -> TurningRecords:
    if not isinstance(params, dict) or not isinstance(module_params, dict):
        raise EngineError(f"the job's params and module_params must be objects; {FIX}")
    if params.get("profile") is None:
        return undrawn_records(params, module_params)
    outline = profile_points(params.get("profile"), "params.profile")
    part = part_polygon(outline)
    zs, rs = [p[0] for p in outline], [p[1] for p in outline]
    stock = stored_stock(params)
    change = (number(params, "tool_change_x"), number(params, "tool_change_z"))
    records = TurningRecords(part, stock, max(zs), min(zs), max(rs), change)
    for n, kind in operation_kinds(module_params).items():
        prep = module_params.get(f"prep:{n}") or {}
        records.operations[n] = Operation(n, kind, _whole(prep.get("tool")), _whole(prep.get("tool_offset")))
        if kind == "THREAD":
            records.threads[n] = thread_region(module_params[f"cutmotion:{n}"].get("paths"), n)
    return records


def undrawn_records(params: dict, module_params: dict) -> TurningRecords:
    """A class job's records: no part, no tool-change position, no operations; the blank its
    params state, if they do. Operations without a drawing's profile are a drawing job whose
    profile is gone, refused rather than proved as less than it is (fail closed)."""
    if operation_kinds(module_params):
        raise EngineError(f"the job has operations (module_params cutmotion:n) but no params.profile: a turning "
                          f"job is proved against its drawing's profile; {FIX}")
    stock = stored_stock(params)
    empty = Polygon()
    return TurningRecords(empty, stock, 0.0, 0.0, 0.0, None, drawn=False)


def stored_stock(params: dict) -> tuple[float, float, float] | None:
    """(z_front, z_back, radius) of the blank the params state (params.stock_diameter, mm, with
    stock_z_front and stock_z_back), or None; a blank with no length or no diameter is refused."""
    if params.get("stock_diameter") is None:
        return None
    z_front, z_back = number(params, "stock_z_front"), number(params, "stock_z_back")
    diameter = number(params, "stock_diameter")
    if not (diameter > 0 and z_front > z_back):
        raise EngineError(f"the blank Ø{diameter:g} Z{z_front:g}…{z_back:g} (params.stock_diameter, stock_z_front, "
                          "stock_z_back) must have a diameter > 0 and its front face in front of its back end "
                          f"(stock_z_front > stock_z_back); {FIX}")
    return z_front, z_back, diameter / 2.0


def operation_kinds(module_params: dict) -> dict[int, str]:
    kinds = {}
    for name, values in module_params.items():
        t, _, n = str(name).partition(":")
        if t == "cutmotion" and n.isdecimal() and isinstance(values, dict) and values.get("kind") in KINDS:
            kinds[int(n)] = values["kind"]
    return kinds


def thread_region(paths, n: int) -> BaseGeometry:
    """The drawn thread: between its crest and root lines (two axial lines, design notes §8)."""
    points = [p for path in (paths or []) for p in profile_points(path, f"module_params.cutmotion:{n}.paths")]
    if len(points) < 2:
        raise EngineError(f"module_params.cutmotion:{n}.paths must hold the thread's crest and root lines; {FIX}")
    zs, rs = [p[0] for p in points], [p[1] for p in points]
    return box(min(zs), min(rs), max(zs), max(rs))


def part_polygon(outline: list[Point]) -> BaseGeometry:
    """The finished part: the half-profile closed along the axis (r = 0) when it does not close
    itself, with its mirror image below the axis (whole(): the axis lies inside the part)."""
    points = list(outline)
    if math.dist(points[0], points[-1]) > 1e-6:
        points = [(points[0][0], 0.0), *points, (points[-1][0], 0.0)]
    polygon = Polygon(points)
    return whole(polygon if polygon.is_valid else polygon.buffer(0))


def whole(half: BaseGeometry) -> BaseGeometry:
    """A half-plane region with its mirror below the axis: a solid of revolution's section, in
    which a point on the axis lies inside (not on the boundary of) the material around it."""
    return unary_union([half, scale(half, yfact=-1.0, origin=(0.0, 0.0))])


def profile_points(items, where: str) -> list[Point]:
    """The segments' points in order, arcs as fine polylines; a segment that is not
    ["line", z0, r0, z1, r1] or ["arc", z0, r0, z1, r1, zc, rc, ccw] is refused."""
    if not isinstance(items, list) or not items:
        raise EngineError(f"{where} must be a non-empty list of segments; {FIX}")
    points: list[Point] = []
    for item in items:
        if not (isinstance(item, list) and item and item[0] in ("line", "arc")):
            raise EngineError(f"{where}: {item!r} is not a line or arc segment; {FIX}")
        values = [_finite(value, where) for value in item[1:7]]
        if item[0] == "line" and len(values) == 4:
            points += [(values[0], values[1]), (values[2], values[3])]
        elif item[0] == "arc" and len(item) == 8:
            points += arc_points((values[0], values[1]), (values[2], values[3]), (values[4], values[5]),
                                 bool(item[7]))
        else:
            raise EngineError(f"{where}: {item!r} has the wrong number of values; {FIX}")
    return points


def arc_points(start: Point, end: Point, centre: Point, ccw: bool) -> list[Point]:
    """Start, end and the points between on the circle about `centre` (ccw: Z right, r up)."""
    radius = math.dist(start, centre)
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    sweep = (a1 - a0) % math.tau if ccw else -((a0 - a1) % math.tau)
    step = 2.0 * math.sqrt(2.0 * ARC_SAGITTA_MM / radius) if radius > ARC_SAGITTA_MM else math.pi
    pieces = min(MAX_ARC_PIECES, max(1, math.ceil(abs(sweep) / step)))
    inner = [(centre[0] + radius * math.cos(a0 + sweep * i / pieces),
              centre[1] + radius * math.sin(a0 + sweep * i / pieces)) for i in range(1, pieces)]
    return [start, *inner, end]


def number(values: dict, name: str) -> float:
    return _finite(values.get(name), f"params.{name}")


def _finite(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise EngineError(f"{where} = {value!r} must be a number; {FIX}")
    return float(value)


def _whole(value) -> int | None:
    return value if type(value) is int else None
