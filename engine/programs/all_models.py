"""Importing this module registers every model with engine.gears.models (the hobbing models and
the turning names model): the one import the planner, the release gate and the commands that ask
for a model make first, since the registry refuses to answer until every model node is in it."""
from .. import turning  # noqa: F401  (registers the turning names model)
from ..hobbing import models  # noqa: F401  (registers every hobbing model)
