"""What a turning job assumes where the drawing and the flags say nothing: shown in the
CLI's help, stored as job parameters (so SQL can change them), reported as notes."""
from __future__ import annotations

DEFAULT_LATHE = "lathe-iso"
CLEARANCE = 2.0              # mm: rapid moves stop this far from the material
TOOL_CHANGE_DISTANCE = 50.0  # mm beyond everything drawn, radially and axially, without a POINT
STOCK_MARGIN = 2.0           # mm on the diameter: default blank over the profile's largest diameter
DEFAULT_SPEED = 800.0        # r/min for an operation layer without @S
DEFAULT_FEED = 150.0         # mm/min for an operation layer without @F
DEFAULT_THREAD_DEPTH_PER_PASS = 0.2   # mm, a thread layer without @D
DEFAULT_INFEED_ANGLE = 0.0   # degrees, a thread layer without @A: radial infeed

# Profile-only drawings: radial depth per rough pass (mm), allowance left by roughing (mm),
# tool, spindle (r/min), feed (mm/min).
PROFILE_DEFAULTS = {"rough_depth": 1.0, "allowance": 0.2, "tool": 1, "speed": DEFAULT_SPEED, "feed": DEFAULT_FEED}
