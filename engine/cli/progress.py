"""The progress bar of long commands (refactor, batches of instantiate): on stderr, and only
when stderr is a terminal, so a cron job's log and a pipe get no bar."""
from __future__ import annotations

import sys
from contextlib import contextmanager

import click


@contextmanager
def progress_bar(label: str):
    """Yield the library's progress callback, `update(stage, done, total)`, drawing a bar on a
    terminal; None (no callback) when stderr is not one."""
    if not sys.stderr.isatty():
        yield None
        return
    with click.progressbar(length=1, label=label, file=sys.stderr) as bar:
        def update(stage, done, total):
            bar.length = max(total, 1)
            bar.label = stage
            bar.update(done - bar.pos)
        yield update
        bar.update((bar.length or 0) - bar.pos)   # the length is set (at least 1) by the first update
