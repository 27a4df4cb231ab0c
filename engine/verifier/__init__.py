"""The fail-closed program verifier (design notes §6, §7): every line a program emits, read with
the grammar of the machine's dialect and checked against the machine before anything is stored
or written. What it cannot read as plain blocks it refuses (engine.verifier.program)."""
from . import expanders  # noqa: F401  (registers the dialects' expanders)
from .limits import check_table_speed
from .program import verify_program
from .refusals import LimitError

__all__ = ["LimitError", "check_table_speed", "verify_program"]
