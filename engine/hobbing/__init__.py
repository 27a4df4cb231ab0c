"""Hobbing models: gear + hob + machine + process choices → the parameters of a template.
Importing this package registers every model with engine.gears.models."""
from . import crowned, cylindrical, duplex, taper, worm_wheel  # noqa: F401  (each registers its model)
