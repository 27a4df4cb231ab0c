"""The fail-closed program verifier (design notes §6, §7): every line a program emits, read with
the grammar of the machine's dialect and checked against the machine before anything is stored
or written. What it cannot read as plain blocks it refuses (engine.verifier.program). A dialect's
expander is imported with its first program (engine.verifier.expansion.EXPANDER_MODULES)."""
from .limits import check_table_speed
from .program import verify_program
from .refusals import LimitError

__all__ = ["LimitError", "check_table_speed", "verify_program"]
