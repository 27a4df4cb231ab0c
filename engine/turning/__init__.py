"""Turning jobs from DXF drawings (design notes §8): tool paths, the turning model that
turns a job's parameters into the moves its template prints, plots. Importing this package
registers the turning names model with engine.gears.models (for `engine lint`)."""
from . import names  # noqa: F401  (registers the turning names model)
