"""Which model serves which gear class: the nearest ancestor that has one. Models register
themselves here (`@register_model("cylindrical")` on the class), as ezdxf's entities do, so the
gears section never imports the hobbing or turning sections above it: importing
engine.hobbing.models or engine.turning registers their models; engine.programs.all_models,
which the programs, release and command-line code that asks for a model imports first, defers
each to its first use (defer_model), so a command imports only the models it plans with."""
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
# A node whose model module is not imported yet: the function that imports it (given by
# engine.programs.all_models, which may name the sections above), so a command imports the model
# it plans with and not the others (issue 28: start-up). It counts as registered.
DEFERRED: dict[str, Callable[[], object]] = {}


def register_model(gear_class: str) -> Callable[[type], type]:
    """Class decorator: one instance of the model serves `gear_class` and the classes below it."""
    _refuse_unknown_node(gear_class)

    def register(model_type: type) -> type:
        MODELS[gear_class] = model_type()
        return model_type
    return register


def defer_model(gear_class: str, load: Callable[[], object]) -> None:
    """`load()` imports the module that registers the model of `gear_class`, when it is first asked for."""
    _refuse_unknown_node(gear_class)
    DEFERRED[gear_class] = load


def _refuse_unknown_node(gear_class: str) -> None:
    if gear_class not in MODEL_NODES:
        raise EngineError(f"internal error: model node {gear_class!r} is not in MODEL_NODES "
                          "(engine.gears.models); add it there")


def registered_models() -> dict[str, NamedModel]:
    """The registry, every deferred model imported, refused unless every model node is registered
    (or deferred): a caller that reached a model before engine.programs.all_models (or
    engine.hobbing.models and engine.turning) was imported would otherwise see a class as
    having none, or as having its ancestor's model (fail closed)."""
    _refuse_unregistered()
    for node in MODEL_NODES:
        _model_of_node(node)
    return MODELS


def _refuse_unregistered() -> None:
    missing = [node for node in MODEL_NODES if node not in MODELS and node not in DEFERRED]
    if missing:
        raise EngineError(f"internal error: gear models not registered: {', '.join(missing)}; import "
                          "engine.programs.all_models (or engine.hobbing.models and engine.turning) before "
                          "asking for one")


def _model_of_node(node: str) -> NamedModel:
    """The node's model, its module imported now if it was deferred."""
    if node not in MODELS:
        DEFERRED[node]()
    if node not in MODELS:
        raise EngineError(f"internal error: importing the model module of {node!r} did not register it")
    return MODELS[node]


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
    _refuse_unregistered()
    for name in ancestry(conn, gear_class):
        if name in MODEL_NODES:
            return _model_of_node(name)
    return None
