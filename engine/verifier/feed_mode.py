"""Feeds per spindle turn held to the feed bound (issue 27). A lathe program may feed per turn
(840D and LinuxCNC G95, Fanuc G99): F is then mm per turn, and the tool travels F × n mm/min,
n the spindle's r/min. The F word's own bound (engine.verifier.words.MAX_FEED, mm/min) says
nothing of that: F5 at S800 is 4,000 mm/min through the part, F400 a unit slip. So a feed move
in that mode is held to two bounds: F at most MAX_FEED_PER_TURN, and F × n at most MAX_FEED,
with n the most the spindle can turn at that point: S under G97, the clamp (LIMS) under
constant cutting speed G96, the machine's maximum when the program states neither (fail closed)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from .refusals import Refused
from .words import MAX_FEED

if TYPE_CHECKING:
    from ..machines.records import Machine
    from .blocks import Block

# mm per spindle turn: above any turning or drilling insert's feed (roughing inserts run at most
# about 1.5 mm/turn, Sandvik Coromant turning data); a larger F per turn is F written in mm/min.
MAX_FEED_PER_TURN = 2.0
PER_TURN, PER_MINUTE = frozenset({95, 99}), frozenset({94, 98})
CONSTANT_SPEED, FIXED_SPEED = 96, 97
FEED_MOTIONS = (1, 2, 3)            # a thread's lead is bounded apart (engine.verifier.limits.check_thread)


class FeedMode:
    """The feed mode and what bounds the spindle's r/min, as the blocks so far set them."""

    def __init__(self, machine: Machine) -> None:
        self.machine = machine
        self.per_turn = False
        self.constant_speed = False
        self.clamp: float | None = None      # LIMS: the r/min G96 may reach

    def take(self, block: Block) -> None:
        if block.g_codes & PER_TURN:
            self.per_turn = True
        elif block.g_codes & PER_MINUTE:
            self.per_turn = False
        if CONSTANT_SPEED in block.g_codes:
            self.constant_speed = True
        elif FIXED_SPEED in block.g_codes:
            self.constant_speed = False
        if "LIMS" in block.values:
            self.clamp = block.values["LIMS"]

    def check(self, block: Block, feed: float | None, speed: float | None) -> None:
        """Refused: a feed move per turn whose F, or F × the highest r/min, exceeds its bound."""
        if not self.per_turn or block.motion not in FEED_MOTIONS or feed is None:
            return
        if feed > MAX_FEED_PER_TURN:
            raise Refused(f"F{feed:g} per spindle turn (G95/G99) exceeds {MAX_FEED_PER_TURN:g} mm/turn, more than "
                          "any turning insert feeds: a feed in mm/min written in feed-per-turn mode?")
        turns = self._highest_turns(speed)
        if feed * turns > MAX_FEED:
            raise Refused(f"F{feed:g} mm/turn at up to {turns:g} r/min feeds {feed * turns:g} mm/min, above "
                          f"{MAX_FEED:g} (mm/min, about a rapid traverse)")

    def _highest_turns(self, speed: float | None) -> float:
        if self.constant_speed:
            return self.clamp if self.clamp is not None else self.machine.spindle_max
        return speed if speed is not None else self.machine.spindle_max
