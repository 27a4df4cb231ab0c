"""Process choices of a hobbing job: what the engineer decides, switched on in template rows."""
from __future__ import annotations

import msgspec
from msgspec.structs import replace

from ..errors import EngineError, InputError

SINGLE_CUT_MAX_MODULE = 3.0   # m_n ≤ about 3: one cut to full depth is common (§B14)
# Radial allowance for shaving or grinding: tenths of a mm in practice; the paper's 2.5 mm is the
# most anyone asked for (§D), more would leave the tooth unformed.
ALLOWANCE_MAX = 2.5

# Axial pass direction per cut (rough, finish). Climb: the hob enters at the top face and
# feeds down; conventional: it enters below the blank and feeds up (§B13). The paper's
# example uses conventional for roughing and climb for finishing (逆—顺铣).
FEED_MODES = {
    "climb": (True, True),
    "conventional": (False, False),
    "conventional-climb": (False, True),
}
# The model's first feed mode when the user gives none (Choices.feed_mode None): climb, the
# engine's habit before issue 29. The search (engine.programs.job_search) may take another one
# when the first does not fit; a mode the user gave is never changed.
DEFAULT_FEED_MODE = "climb"
# A cluster gear may feed each unit its own way: "climb/conventional" is unit 1 climb, unit 2
# conventional. Fed toward each other, both passes leave their unit into the gap between the
# units, where only the short run-out of the face they leave is needed, not a full run-in
# (engine.hobbing.duplex: the gap holds the hob's reach into the other unit and that run-out).
UNIT_SEPARATOR = "/"
UNIT_FEED_MODES = ("climb/conventional", "conventional/climb")
WORM_FEEDS = ("radial", "tangential")


class Choices(msgspec.Struct, frozen=True):
    """What the user chose for a new hobbing job (the options of engine instantiate); None leaves it to the model."""
    cuts: int | None = None            # 1 = finish only, 2 = rough then finish; None = by module
    finish_stock: float | None = None  # radial stock left by the rough cut, mm
    coolant: bool = True
    feed_mode: str | None = None       # None = the model's choice (DEFAULT_FEED_MODE first)
    shift_y: float = 0.0               # hob shift position for this part, mm (0 = no shift)
    shift_per_part: float = 0.0        # shift step per part, mm (0 = no shifting from part to part)
    tailstock: bool = True             # clamp the workpiece with the tailstock (the paper's example)
    worm_feed: str = "radial"          # worm wheels: radial plunge or tangential feed along Y
    allowance: float = 0.0             # radial process allowance left at the final cut for shaving/grinding, mm (§B14)
    fixture: str | None = None         # the work-holding's id (--fixture); None: chosen (issue 29)

    def __post_init__(self):
        if self.feed_mode is not None and not _known_mode(self.feed_mode):
            raise EngineError(f"feed mode {self.feed_mode!r} is not one of {', '.join(FEED_MODES)}, nor one "
                              f"per unit of a cluster gear (unit 1's/unit 2's, e.g. {UNIT_FEED_MODES[0]})")
        if self.worm_feed not in WORM_FEEDS:
            raise EngineError(f"worm feed {self.worm_feed!r} is not one of {', '.join(WORM_FEEDS)}")
        if self.shift_per_part < 0:
            raise EngineError(f"shift per part {self.shift_per_part:g} mm must not be negative")
        if not 0 <= self.allowance <= ALLOWANCE_MAX:
            raise EngineError(f"allowance {self.allowance:g} mm must be between 0 and {ALLOWANCE_MAX:g} mm "
                              "(radial stock left for shaving or grinding)")
        if self.shift_per_part and self.shift_y:
            raise EngineError("give either a fixed shift position (--shift-y) or a shift per part "
                              "(--shift-per-part), not both")

    def cut_count(self, module: float) -> int:
        if self.cuts is not None:
            return self.cuts
        return 1 if module <= SINGLE_CUT_MAX_MODULE else 2

    def stock(self, module: float) -> float:
        """0.3–1.0 mm, more for larger modules (§B14)."""
        if self.finish_stock is not None:
            return self.finish_stock
        return min(1.0, max(0.3, 0.15 * module))

    @property
    def mode(self) -> str:
        """The feed mode the job is cut with: the one given, else the model's first choice."""
        return self.feed_mode if self.feed_mode is not None else DEFAULT_FEED_MODE

    def climb(self, cut_number: int, cut_count: int) -> bool:
        """Whether cut `cut_number` (1 = rough, 2 = finish) runs climb; a single cut takes the
        roughing direction (the paper's single rough cut, conventional-climb mode). A mode per
        unit is read through for_unit first."""
        rough, finish = FEED_MODES[self.mode]
        return rough if cut_number == 1 or cut_count == 1 else finish

    def for_unit(self, number: int, units: int, gear_id: int) -> Choices:
        """The choices unit `number` of a gear of `units` units is cut with: its own feed mode where
        the mode names one per unit, else these. A mode per unit on a gear of another number of
        units is refused."""
        modes = self.mode.split(UNIT_SEPARATOR)
        if len(modes) == 1:
            return self
        if len(modes) != units:
            raise InputError(f"gear {gear_id}: feed mode {self.mode} names one for each of {len(modes)} units; "
                              f"the gear has {units}: give one of {', '.join(FEED_MODES)}")
        return replace(self, feed_mode=modes[number - 1])

    def directions(self, cut_count: int, units: int) -> tuple:
        """The pass directions (climb or not) of every cut of every unit: what makes two modes the
        same job (a single cut runs the roughing direction only)."""
        return tuple(self.for_unit(unit, units, 0).climb(number, cut_count)
                     for unit in range(1, units + 1) for number in (1, 2)[2 - cut_count:])

    @property
    def shifting(self) -> bool:
        return self.shift_y != 0 or self.shift_per_part > 0


def refuse_feed_mode(gear, choices: Choices) -> None:
    """A gear cut without axial passes (a worm wheel: a radial plunge or a tangential pass) has no
    feed direction to choose: a --feed-mode given for it is refused, not written into the header
    over cuts it does not describe (new-user review 29)."""
    if choices.feed_mode is not None:
        raise InputError(f"gear {gear.id}: class {gear.gear_class} is fed {choices.worm_feed}ly (--worm-feed), it has "
                         f"no axial pass to cut {choices.feed_mode}; leave out --feed-mode")


def _known_mode(mode: str) -> bool:
    """A mode of FEED_MODES, or two of them (unit 1's and unit 2's) joined by UNIT_SEPARATOR; a
    stored job's params.feed_mode may be any JSON value (a number is no mode)."""
    if not isinstance(mode, str):
        return False
    modes = mode.split(UNIT_SEPARATOR)
    return len(modes) <= 2 and all(one in FEED_MODES for one in modes)
