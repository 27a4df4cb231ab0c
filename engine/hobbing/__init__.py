"""Hobbing models: gear + hob + machine + process choices → the parameters of a template."""
