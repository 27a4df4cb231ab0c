"""`engine`: the command line, a thin shell over the library (nothing outside engine.cli imports it)."""
from .app import main

__all__ = ["main"]
