"""A batch planned in worker processes is stored slice by slice as the slices come back, while
the workers plan the next ones (issue 28: storing a batch through COPY was a fifth of one
process's time, and ran alone after the planning, so two workers made 1.6x one process's
programs per second instead of the 1.7x asked). Everything is stored inside the batch's one
transaction: a bad gear (without --skip-bad), a file that cannot be written or a refused store
rolls all of it back, and nothing is stored, as before."""
from __future__ import annotations

from typing import TYPE_CHECKING

from .batches import Bad
from .storage import Batch, store_slice, stored_batch

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .outputs import ProgramFiles


class StreamedStore:
    """Stores each slice of a batch's outcomes (in gear order) as it is given one."""

    def __init__(self, conn: Connection, skip_bad: bool):
        self.conn, self.skip_bad = conn, skip_bad
        self.program_ids: list[int] = []
        self.texts: dict = {}
        self.used = False      # given a slice: the batch was planned in workers
        self.stopped = False   # a bad gear without --skip-bad: the batch will store nothing

    def __call__(self, outcomes: list) -> None:
        self.used = True
        if self.stopped:
            return
        if not self.skip_bad and any(isinstance(outcome, Bad) for outcome in outcomes):
            self.stopped = True   # planning goes on, so that the refusal names every bad gear
            return
        good = [outcome for outcome in outcomes if not isinstance(outcome, Bad)]
        if good:
            stored = store_slice(self.conn, good)
            self.program_ids += stored.program_ids
            self.texts.update(stored.texts)

    def batch(self, encoded: list, out, files: ProgramFiles) -> Batch:
        """The batch stored (all its good programs, `encoded`), its files given the stored texts."""
        assert len(self.program_ids) == len(encoded), "a streamed batch stored other programs than it reports"
        files.replace_texts(self.texts)
        return stored_batch(encoded, self.program_ids, out)
