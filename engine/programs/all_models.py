"""Importing this module registers every model with engine.gears.models (the hobbing models and
the turning names model): the one import the planner, the release gate and the commands that ask
for a model make first, since the registry refuses to answer until every model node is in it.
Each model's module is imported when its model is first asked for (engine.gears.models.DEFERRED),
so `engine instantiate --gear 42` imports the cylindrical model and not the taper, duplex,
crowned or worm-wheel ones (issue 28: start-up)."""
from __future__ import annotations

from functools import partial
from importlib import import_module

from ..gears.models import MODELS, defer_model

# model node -> the module whose import registers its model (@register_model)
MODEL_MODULES = {"cylindrical": "engine.hobbing.cylindrical", "duplex": "engine.hobbing.duplex",
                 "taper": "engine.hobbing.taper", "crowned": "engine.hobbing.crowned",
                 "worm_wheel": "engine.hobbing.worm_wheel", "turning": "engine.turning.names"}

for _node, _module in MODEL_MODULES.items():
    if _node not in MODELS:
        defer_model(_node, partial(import_module, _module))
