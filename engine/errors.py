"""Errors a user can act on: one line that names the thing and what to do."""


class EngineError(Exception):
    """A handled error. The CLI prints its message on one line and exits 1."""


def csv_problem(error) -> str:
    """What a csv.Error (strict reading) means for the person who wrote the file."""
    if "unexpected end of data" in str(error):
        return "a quote opened here is never closed; close it (a quote inside a cell is written \"\")"
    return f"not valid CSV ({error})"
