"""What a line is for, by its linetype or its layer's name, and which layer holds the part
when layer 0 is empty (issue 17).

CAD drawings mark centre lines with a dash-dot linetype (CENTER, DASHDOT, ISO 04/08/10) or
keep them on a layer named for them (center, Mitte, Achse, axis), and hidden edges with a
dashed linetype (HIDDEN, DASHED, ISO 02) or on a layer like 'hidden' or 'verdeckt'. Neither
is part of a turned outline: a centre line may be the turning axis, a hidden edge is never
cut from outside. The rules are the tables LINE_ROLES (first match wins, linetype before
layer name, both compared in upper case).
"""
from __future__ import annotations

from functools import lru_cache

import msgspec

from .profile import END_MATCH_TOLERANCE_MM, chain_segments
from .read import DxfError

CENTRE, HIDDEN = "centre line", "hidden line"
# A layer of more pieces than this (flattened curves, hatching, a site plan) is not looked at
# as the part's: the choice stays fast and such a layer is named with --profile-layer.
MAX_CHOICE_SEGMENTS = 20_000


class LineRole(msgspec.Struct, frozen=True):
    role: str
    linetype_words: tuple[str, ...]   # a linetype whose name contains one of these
    layer_words: tuple[str, ...]      # a layer whose name contains one of these


LINE_ROLES = (
    LineRole(CENTRE, ("CENTER", "CENTRE", "DASHDOT", "ISO04", "ISO08", "ISO10", "STRICHPUNKT"),
             ("CENTER", "CENTRE", "MITTE", "ACHSE", "AXIS")),
    LineRole(HIDDEN, ("HIDDEN", "DASHED", "ISO02", "VERDECKT", "STRICH"),
             ("HIDDEN", "VERDECKT", "DASHED")),
)
UNSET_LINETYPES = ("", "BYLAYER", "BYBLOCK")


def effective_linetype(entity, layer_linetypes: dict[str, str], layer: str) -> str:
    """The entity's own linetype, else its layer's (DXF: BYLAYER is the default)."""
    own = str(entity.dxf.get("linetype", "BYLAYER") or "").upper()
    return own if own not in UNSET_LINETYPES else layer_linetypes.get(layer.upper(), "").upper()


def line_role(entity, layer: str, layer_linetypes: dict[str, str]) -> str | None:
    """CENTRE, HIDDEN or None (an outline or anything else) for one entity."""
    return role_of(effective_linetype(entity, layer_linetypes, layer), layer.upper())


@lru_cache(maxsize=1024)
def role_of(linetype: str, name: str) -> str | None:
    """The role a linetype (upper case) or else a layer name (upper case) gives a line."""
    for rule in LINE_ROLES:
        if any(word in linetype for word in rule.linetype_words):
            return rule.role
    for rule in LINE_ROLES:
        if any(word in name for word in rule.layer_words):
            return rule.role
    return None


def layer_linetypes(doc) -> dict[str, str]:
    return {layer.dxf.name.upper(): str(layer.dxf.get("linetype", "") or "") for layer in doc.layers}


def drawing_layers(doc) -> list[str]:
    """Every layer of the drawing: the LAYER table's, then those only entities name (of model
    space and of the blocks it inserts). DXF lets an entity use a layer the table lacks (the
    reader then takes the default layer properties), and some exporters write no table entry
    for the layers they use: such a layer is the drawing's as much as any."""
    names = {layer.dxf.name.upper(): layer.dxf.name for layer in doc.layers}
    for entity in entities_with_blocks(doc):
        names.setdefault(entity.dxf.layer.upper(), entity.dxf.layer)
    return list(names.values())


def entities_with_blocks(doc):
    """Model space's entities and those of every block it inserts (the block's own, once)."""
    modelspace = doc.modelspace()
    yield from modelspace
    inserted = {entity.dxf.name for entity in modelspace.query("INSERT")}
    for name in sorted(inserted):
        if name in doc.blocks:
            yield from doc.blocks.get(name)


def existing_layer(doc, name: str) -> str:
    """The layer as the drawing spells it (DXF layer names ignore case), from the LAYER table or
    from the entities that use it; a name the drawing does not have is refused with the names it
    has, so the user can pick the outline's."""
    layers = {layer.upper(): layer for layer in drawing_layers(doc)}
    if name.upper() in layers:
        return layers[name.upper()]
    if name == "0":
        return name
    names = ", ".join(repr(layer) for layer in layers.values())
    raise DxfError(f"profile layer {name!r} is not in the drawing; its layers are {names}")


def axis_contours(segments, tolerance: float = END_MATCH_TOLERANCE_MM) -> int:
    """How many chains of a layer could be a turned part: a closed contour that touches or
    straddles the axis (drawing Y = 0), or a half-contour with both ends on it; or the same
    about a vertical axis (drawing X = 0, engine.drawings.vertical) right of it."""
    return sum(1 for chain in chain_segments(segments) if on_axis(chain, 1, tolerance)
               or (chain.bounds[0] >= -tolerance and on_axis(chain, 0, tolerance)))


def on_axis(chain, across: int, tolerance: float) -> bool:
    """The chain touches or straddles the axis along which coordinate `across` (1: drawing Y,
    the radius; 0: drawing X) is 0: closed, or open with both ends on it."""
    low, high = chain.bounds[2 * across], chain.bounds[2 * across + 1]
    if chain.closed:
        return low <= tolerance < high
    return abs(chain.start[across]) <= tolerance and abs(chain.end[across]) <= tolerance \
        and max(abs(low), abs(high)) > tolerance


def chosen_profile_layer(segments_by_layer: dict[str, list]) -> tuple[str, str] | None:
    """(layer, note) when layer 0 is empty and exactly one layer holds exactly one contour on
    the axis; None when no layer does (the caller says layer 0 has no profile); DxfError naming
    the layers when two or more do, since either could be the part."""
    found = sorted(name for name, segments in segments_by_layer.items()
                   if segments and len(segments) <= MAX_CHOICE_SEGMENTS and axis_contours(segments) == 1)
    if len(found) > 1:
        named = " and ".join(repr(name) for name in found)
        raise DxfError(f"layer 0 is empty and layers {named} each hold one contour on the axis; "
                       f"name the part's layer with --profile-layer (e.g. --profile-layer {found[0]!r})")
    if not found:
        return None
    return found[0], (f"layer 0 is empty: the profile was taken from layer {found[0]!r}, the only layer "
                      "with one contour touching or straddling the axis (--profile-layer names another)")
