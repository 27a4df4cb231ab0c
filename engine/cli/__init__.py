"""`engine`: the command line, a thin shell over the library. Nothing outside engine.cli imports it
but engine.__main__ (`python -m engine`)."""
from .app import main

__all__ = ["main"]
