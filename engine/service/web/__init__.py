"""The web view of `engine serve` (issue 32): server-rendered pages of gears, jobs, programs,
classes, releases and machines, each also as JSON (`Accept: application/json`, the keys of the
CLI's `--json`). One module per concept registers its routes in PAGE_MODULES (app.py)."""
