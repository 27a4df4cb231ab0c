"""read_drawing: a DXF turning drawing (design notes §8) → Drawing, or one DxfError line.

Layer `0` holds the profile and at most one POINT (the tool-change position); layers named
`1` … `n` hold the tool-centre path of operation n and its @-codes as TEXT/MTEXT. Only
model space counts. Layers with other names (dimensions, hatch, centre lines) are left
out and listed in `notes`; so are TEXTs on layer 0 (no @-codes there). Lengths come out
in mm, in machine coordinates (z, radius), scaled by $INSUNITS (unitless: mm, unless the header
says English measurement; see units_doubted). @-code
values are taken as written: r/min, mm/min or mm/rev, mm — the seed's units, whatever
the drawing's length unit.
"""
from __future__ import annotations

from collections import Counter, defaultdict
from pathlib import Path
from typing import NamedTuple

import msgspec

from ..memory import no_cycle_collection
from .codes import CodeText, layer_codes
from .entities import (
    FLATTEN_TOLERANCE_MM,
    HANDLERS,
    MAX_COORDINATE_MM,
    Context,
    check_finite,
    check_reach,
    inserted_entities,
    named_on_failure,
    segments_of,
    unit_scale,
)
from .geometry import Line, Segment
from .layers import CENTRE, HIDDEN, chosen_profile_layer, existing_layer, layer_linetypes, line_role
from .outline import hatch_polygons, profile_of
from .profile import Profile, chain_segments, scaled
from .read import DxfError, ezdxf_warnings, load_drawing_file, summarised
from .side_view import Marks
from .vertical import vertical_doubt

PROFILE_LAYER = "0"
OR_NAME_IT = " or name its layer with --profile-layer"
TEXT_TYPES = ("TEXT", "MTEXT")
# Codes an operation kind cannot do without (a thread cannot be cut without its pitch).
REQUIRED_CODES = {"THREAD": ("thread_pitch",)}


class MachinePoint(NamedTuple):
    """A point in machine coordinates: z and radius in mm (X in a program is the diameter)."""
    z: float
    radius: float

    @property
    def x_diameter(self) -> float:
        return 2.0 * self.radius


class Operation(msgspec.Struct):
    """One operation layer: number n (= its order and tool by convention), kind (@G), the
    other @-codes by name, and its tool-centre path chained into paths (mm, z/radius)."""
    layer: str
    number: int
    kind: str
    codes: dict[str, object]
    paths: list[list[Segment]]

    @property
    def segments(self) -> list[Segment]:
        return [segment for path in self.paths for segment in path]


class Drawing(msgspec.Struct):
    """A drawing that can become a job. repairs: what the tolerant reader and the auditor
    fixed in the file; notes: what the reader assumed or left out (units, other layers,
    entity types without geometry, chains on layer 0 besides the profile)."""
    source: Path
    units: str
    scale_to_mm: float
    profile: Profile
    operations: list[Operation]
    tool_change: MachinePoint | None
    repairs: list[str] = []
    notes: list[str] = []


class LayerContent(msgspec.Struct):
    segments: list[Segment] = []
    centre: list[Segment] = []   # drawn in a centre-line linetype
    entities: int = 0
    texts: list[CodeText] = []
    points: list[tuple[str, tuple[float, float]]] = []


class Collected(msgspec.Struct):
    layers: dict[str, LayerContent] = msgspec.field(default_factory=lambda: defaultdict(LayerContent))
    skipped: Counter = msgspec.field(default_factory=Counter)
    other_layers: Counter = msgspec.field(default_factory=Counter)
    profile_layer: str | None = PROFILE_LAYER   # None: every layer is collected, the profile's chosen after
    linetypes: dict[str, str] = {}   # layer name (upper case) → its linetype
    centre_lines: list[Line] = []
    hidden: Counter = msgspec.field(default_factory=Counter)
    hidden_lines: list[Segment] = []
    hatches: list[list[tuple[float, float]]] = []


def read_drawing(path: str | Path, profile_layer: str | None = None) -> Drawing:
    """Read a turning drawing; DxfError (one line naming the layer, handle or text) if it
    cannot become a job. profile_layer: where the part outline is (real CAD drawings keep
    it on a layer like 'outline' rather than the seed-000 convention's layer 0); None: layer
    0, or when that is empty the one layer holding one contour on the axis (layers)."""
    with ezdxf_warnings() as warnings, no_cycle_collection():
        drawing_file = load_drawing_file(path)
        units, scale, assumed = unit_scale(drawing_file.doc.header.get("$INSUNITS"))
        given = None if profile_layer is None else existing_layer(drawing_file.doc, profile_layer)
        collected = collect(drawing_file.doc.modelspace(), scale, given, layer_linetypes(drawing_file.doc))
    chosen = choose_layer(collected, scale) if given is None else []
    profile_layer = collected.profile_layer
    assert profile_layer is not None   # the one given, or choose_layer's
    layer0 = collected.layers.pop(profile_layer, LayerContent())
    chosen += all_dash_dot(layer0, collected, profile_layer)
    if not layer0.segments:
        raise DxfError(no_geometry_message(collected))
    profile, outline_notes, chains = profile_of([scaled(s, scale) for s in layer0.segments],
                                                scaled_marks(collected, scale), profile_layer)
    side_view = bool(outline_notes)   # or a vertical axis: no tool-change POINT, no operation layers
    outline_notes += units_doubted(drawing_file, assumed)
    operations = [operation(name, number, collected.layers[name], scale, profile.mirrored)
                  for number, name in operation_layers(collected.layers)]
    if side_view and any(operations):
        raise DxfError(f"layer {profile_layer} is not drawn in the seed-000 convention ({outline_notes[0]}); "
                       "operation layers need it (the half-profile above the axis at drawing Y = 0): redraw it so")
    tool_change = None if side_view else tool_change_point(layer0.points, scale, profile.mirrored)
    notes = (chosen + outline_notes + reading_notes(units, assumed, collected, profile) + summarised(warnings)
             + left_out_notes(profile_layer, layer0, chains, side_view)
             + vertical_doubt(profile, profile_layer, side_view))
    return Drawing(drawing_file.path, units, scale, profile, [op for op in operations if op],
                   tool_change, drawing_file.repairs, notes)


def left_out_notes(layer: str, content: LayerContent, chains: list, side_view: bool) -> list[str]:
    """What the profile layer holds besides the profile: other chains, or a side view's POINTs."""
    if side_view:
        return [f"layer {layer}: {len(content.points)} POINT(s) left out (only a half-profile on drawing "
                "Y 0 has a tool-change point)"] if content.points else []
    if len(chains) <= 1:
        return []
    return [f"layer {layer}: {len(chains) - 1} other chain(s) are not part of the profile, left out"]


def scaled_marks(collected: Collected, scale: float) -> Marks:
    return Marks([scaled(s, scale) for s in collected.centre_lines],
                 [[(x * scale, y * scale) for x, y in polygon] for polygon in collected.hatches],
                 [scaled(s, scale) for s in collected.hidden_lines])


def all_dash_dot(layer0: LayerContent, collected: Collected, layer: str) -> list[str]:
    """A profile layer drawn only in a centre-line linetype: its lines are the outline, not centre lines."""
    if layer0.segments or not layer0.centre:
        return []
    layer0.segments, drawn = layer0.centre, {id(s) for s in layer0.centre}
    collected.centre_lines = [s for s in collected.centre_lines if id(s) not in drawn]
    return [f"layer {layer}: every line is drawn in a centre-line linetype; taken as the outline"]


def choose_layer(collected: Collected, scale: float) -> list[str]:
    """Layer 0 unless it is empty; then the one named layer with one contour on the axis (a note
    says so). Layers not chosen are counted among the other layers."""
    # A numbered layer without @-codes is no operation: when layer 0 is empty, it may hold the part.
    named = {name: content for name, content in collected.layers.items()
             if name != PROFILE_LAYER and (operation_number(name) is None or not content.texts)}
    chosen = None
    layer0 = collected.layers.get(PROFILE_LAYER, LayerContent())
    if not (layer0.segments or layer0.centre):
        chosen = chosen_profile_layer({name: [scaled(s, scale) for s in content.segments]
                                       for name, content in named.items()})
    collected.profile_layer = chosen[0] if chosen else PROFILE_LAYER
    for name, content in named.items():
        if name != collected.profile_layer and operation_number(name) is None:
            collected.other_layers[name] += content.entities
            del collected.layers[name]
    return [chosen[1]] if chosen else []


def operation_number(layer: str) -> int | None:
    """n for an operation layer named n (1, 2, …; '01' too), else None."""
    name = layer.strip()
    return int(name) if name.isdecimal() and int(name) > 0 else None


def is_relevant(layer: str, profile_layer: str | None) -> bool:
    return profile_layer is None or layer == profile_layer or operation_number(layer) is not None


def collect(modelspace, scale: float, profile_layer: str | None = PROFILE_LAYER,
            linetypes: dict[str, str] | None = None) -> Collected:
    """One pass over model space: segments, texts and points of the profile layer (every
    layer when it is None) and layers 1 … n, centre lines and hatching of any layer, hidden
    lines counted (scale: drawing units to mm)."""
    sagitta, reach = FLATTEN_TOLERANCE_MM / scale, MAX_COORDINATE_MM / scale
    collected = Collected(profile_layer=profile_layer, linetypes=linetypes or {})
    own = Context(sagitta, reach=reach)
    for entity in modelspace:
        with named_on_failure(entity):
            layer = entity.dxf.layer
            if entity.dxftype() == "INSERT":
                check_finite(entity, own)
                context = Context(sagitta, entity.dxf.handle, reach)
                for effective_layer, part in inserted_entities(entity, layer):
                    take(part, effective_layer, context, collected)
            else:
                take(entity, layer, own, collected)
    return collected


def take(entity, layer: str, context: Context, collected: Collected) -> None:
    kind = entity.dxftype()
    if kind == "HATCH":
        collected.hatches.extend(hatch_polygons(entity))
    # Operation layers hold tool paths in whatever linetype: roles apply to the others.
    role = (line_role(entity, layer, collected.linetypes)
            if kind in HANDLERS and operation_number(layer) is None else None)
    if role == CENTRE:
        check_finite(entity, context)
        segments = segments_of(entity, context)
        collected.centre_lines.extend(s for s in segments if isinstance(s, Line))
        if is_relevant(layer, collected.profile_layer):
            collected.layers[layer].centre.extend(segments)
            collected.layers[layer].entities += 1
        return
    if role == HIDDEN:
        check_finite(entity, context)
        collected.hidden[layer] += 1
        collected.hidden_lines.extend(segments_of(entity, context))
        return
    if not is_relevant(layer, collected.profile_layer):
        collected.other_layers[layer] += 1
        return
    content = collected.layers[layer]
    content.entities += 1
    handle = context.handle or entity.dxf.handle
    check_finite(entity, context)
    if kind in HANDLERS:
        content.segments.extend(segments_of(entity, context))
    elif kind in TEXT_TYPES:
        content.texts.append(CodeText(layer, handle, entity.plain_text()))
    elif kind == "POINT":
        location = entity.dxf.location
        check_reach(entity, context, (location.x, location.y))
        content.points.append((handle, (location.x, location.y)))
    else:
        collected.skipped[kind] += 1


def operation_layers(layers: dict[str, LayerContent]) -> list[tuple[int, str]]:
    """(operation number, layer name) in order; two names for one number is an error."""
    numbered: dict[int, str] = {}
    for name in layers:
        number = operation_number(name)
        if number is None:
            continue
        if number in numbered:
            raise DxfError(f"layers {numbered[number]!r} and {name!r} both mean operation {number}; "
                           "merge them into one layer")
        numbered[number] = name
    return sorted(numbered.items())


def operation(name: str, number: int, content: LayerContent, scale: float,
              mirror: bool) -> Operation | None:
    """The operation on one numbered layer; None for a layer with neither path nor codes."""
    codes = layer_codes(content.texts)
    if not content.segments and not codes:
        return None
    if "kind" not in codes:
        raise DxfError(f"layer {name!r} (operation {number}) has a tool path of {len(content.segments)} "
                       f"segment(s) but no @G code; add a TEXT like '@GROUGH' on that layer "
                       f"(types: ROUGH SLOT FINISH THREAD FACE PART)")
    kind = str(codes.pop("kind"))   # layer_codes reads @G as text
    if not content.segments:
        raise DxfError(f"layer {name!r} (operation {number}, @G {kind}) has no tool path; "
                       "draw the tool-centre path on that layer")
    for required in REQUIRED_CODES.get(kind, ()):
        if required not in codes:
            raise DxfError(f"layer {name!r} (operation {number}, @G {kind}) needs its {required} "
                           "(@P for the thread pitch)")
    paths = chain_segments([scaled(s, scale, mirror) for s in content.segments])
    return Operation(name, number, kind, codes, [chain.segments for chain in paths])


def tool_change_point(points: list[tuple[str, tuple[float, float]]], scale: float,
                      mirror: bool) -> MachinePoint | None:
    if not points:
        return None
    if len(points) > 1:
        handles = ", ".join(handle for handle, _ in points[:6])
        raise DxfError(f"layer 0 has {len(points)} POINTs (handles {handles}); the convention allows "
                       "one, the tool-change position: delete the others or move them to another layer")
    _, (x, y) = points[0]
    return MachinePoint(x * scale, (-y if mirror else y) * scale)


ENGLISH = 0   # $MEASUREMENT: 0 English (imperial), 1 metric


def units_doubted(drawing_file, assumed: bool) -> list[str]:
    """A drawing without units whose header says English measurement ($MEASUREMENT 0) may be in
    inches: refused, since taking it as mm would turn a part 25.4 times too small, and taking it
    as inches would be as wrong for the many metric drawings made from an imperial template
    ($MEASUREMENT sets hatch and linetype defaults, not the coordinate unit). Its dimension
    suffix ($DIMPOST '<>mm') is the drafter's own word that the numbers are millimetres."""
    header = drawing_file.doc.header
    if not assumed or header.get("$MEASUREMENT") != ENGLISH:
        return []
    suffix = str(header.get("$DIMPOST") or "")
    if "mm" in suffix.lower():
        return [f"$MEASUREMENT 0 (English), but dimensions are written in mm ($DIMPOST {suffix!r}): "
                "lengths taken as millimetres"]
    raise DxfError(f"{drawing_file.path.name}: no drawing units ($INSUNITS unset or unitless) and the header says "
                   "English measurement ($MEASUREMENT 0), so its lengths may be inches; set the drawing units "
                   "in the CAD program ($INSUNITS 1 = inches, 4 = millimetres) and save it again")


def reading_notes(units: str, assumed: bool, collected: Collected, profile: Profile) -> list[str]:
    notes = []
    if assumed:
        notes.append("no drawing units ($INSUNITS unset or unitless): lengths taken as millimetres")
    if profile.mirrored:
        notes.append("the profile lies below the axis: mirrored onto it (paths and tool-change point too)")
    if collected.skipped:
        listed = ", ".join(f"{count} {kind}" for kind, count in sorted(collected.skipped.items()))
        notes.append(f"not geometry, left out on layer 0 / operation layers: {listed}")
    if collected.hidden:
        listed = ", ".join(f"{name!r} ({count})" for name, count in sorted(collected.hidden.items()))
        notes.append(f"hidden (dashed) lines left out, never cut from outside: {listed}")
    if collected.other_layers:
        listed = ", ".join(f"{name!r} ({count})" for name, count in sorted(collected.other_layers.items()))
        notes.append(f"layers that are neither the profile's nor an operation number, left out: {listed}")
    return notes


def no_geometry_message(collected: Collected) -> str:
    layer = collected.profile_layer
    elsewhere = {name: len(content.segments) for name, content in collected.layers.items() if content.segments}
    found = ", ".join(f"layer {name!r}: {count} segment(s)" for name, count in sorted(elsewhere.items()))
    found = found or ", ".join(f"layer {name!r}: {count} entities" for name, count in
                               sorted(collected.other_layers.items())[:5])
    return (f"layer {layer} has no profile: no LINE, ARC, CIRCLE, polyline, SPLINE or ELLIPSE on layer {layer} of "
            f"model space ({'found ' + found if found else 'model space has no geometry'}); "
            f"draw the part outline on layer {layer}{OR_NAME_IT if layer == PROFILE_LAYER else ''}")
