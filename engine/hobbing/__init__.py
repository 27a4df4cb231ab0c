"""Hobbing models: gear + hob + machine + process choices → the parameters of a template.
Importing engine.hobbing.models registers every model with engine.gears.models."""
