"""Errors a user can act on: one line that names the thing and what to do."""


class EngineError(Exception):
    """A handled error. The CLI prints its message on one line and exits with `exit_code`: 1,
    nothing stored; 3 (engine.programs.outputs.StoredNotWritten) programs stored, files not written."""
    exit_code = 1



class InputError(EngineError):
    """An input no choice of the search can change (engine.programs.job_search): an unknown or
    unfitting --fixture, a feed mode per unit on a gear of another number of units, two cuts with
    a tangential feed, a worm wheel's module not stated as axial or normal.
    The search stops at it with its own message, not after trying every choice."""
