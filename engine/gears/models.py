"""Which model serves which gear class: the nearest ancestor that has one. Models register
themselves here (`@register_model("cylindrical")` on the class), as ezdxf's entities do, so the
gears section never imports the hobbing or turning sections above it: importing
engine.hobbing.models or engine.turning registers their models, and the programs, release and
command-line code that asks for a model imports them first."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection


class NamedModel(Protocol):
    """What `engine lint` asks of every model: the parameter names a module's rows may read."""

    def parameter_names(self, t: str, n: int) -> frozenset: ...


class HobbingModel(NamedModel, Protocol):
    """What the instantiation asks of a hobbing model (engine.hobbing.cylindrical and its kin)."""
    hob_purpose: str           # which hobs of the library may cut the class (engine.gears.hob_matching)
    cut_shape: str             # the pass its template emits (engine.hobbing.cycle_time.PASSES)

    def shift_travel(self, choices: Any) -> float: ...

    def job(self, gear: Any, gear_class: str, hob: Any, machine: Any, cutting: Any, choices: Any) -> Any: ...


# The model of a node of the group-technology tree serves it and every class below it that has
# no model of its own. Filled by register_model as the model modules are imported.
MODELS: dict[str, NamedModel] = {}
# The nodes that have a model, as data (the gears section names no module above it). All must be
# registered before any is used: with one missing, a class under it would silently get an
# ancestor's model (a taper gear cut as a cylindrical one), so a partial registry is refused too.
MODEL_NODES = ("cylindrical", "duplex", "taper", "crowned", "worm_wheel", "turning")


def register_model(gear_class: str) -> Callable[[type], type]:
    """Class decorator: one instance of the model serves `gear_class` and the classes below it."""
    if gear_class not in MODEL_NODES:
        raise EngineError(f"internal error: model node {gear_class!r} is not in MODEL_NODES "
                          "(engine.gears.models); add it there")

    def register(model_type: type) -> type:
        MODELS[gear_class] = model_type()
        return model_type
    return register


def registered_models() -> dict[str, NamedModel]:
    """The registry, refused unless every model node is registered: a caller that reached a model
    before engine.hobbing.models and engine.turning were imported would otherwise see a class as
    having none, or as having its ancestor's model (fail closed)."""
    missing = [node for node in MODEL_NODES if node not in MODELS]
    if missing:
        raise EngineError(f"internal error: gear models not registered: {', '.join(missing)}; import "
                          "engine.hobbing.models and engine.turning before asking for one")
    return MODELS


CLASS_ANCESTRY = """
WITH RECURSIVE up(name, parent, depth) AS (
    SELECT name, parent, 0 FROM gear_class WHERE name = %s
    UNION ALL
    SELECT g.name, g.parent, up.depth + 1 FROM gear_class g JOIN up ON g.name = up.parent
    WHERE up.depth < 50)
SELECT name FROM up ORDER BY depth"""


def ancestry(conn: Connection, gear_class: str) -> list[str]:
    """The class and its ancestors, nearest first."""
    return [row[0] for row in conn.execute(CLASS_ANCESTRY, (gear_class,))]


def model_for_class(conn: Connection, gear_class: str) -> Any:
    """The model of the class's nearest ancestor that has one (a HobbingModel, or the turning
    names model), or None when no class on the path up has one."""
    models = registered_models()
    for name in ancestry(conn, gear_class):
        if name in models:
            return models[name]
    return None
