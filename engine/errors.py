"""Errors a user can act on: one line that names the thing and what to do."""


class EngineError(Exception):
    """A handled error. The CLI prints its message on one line and exits with `exit_code`: 1,
    nothing stored; 3 (engine.programs.outputs.StoredNotWritten) programs stored, files not written."""
    exit_code = 1

