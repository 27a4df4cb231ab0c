"""The names of a turning job and its templates: operation slots, the job and module
parameters (for `engine lint`). Light on purpose: engine.turning registers its model on import."""
from __future__ import annotations

from ..gears.models import register_model

# Operation slots in the turning templates (rows 1000·n + 10 … 80); a drawing with more
# operation layers is refused. Nine covers the seed's jobs (rough, slot, thread, finish …)
# with room; more slots are more rows, not more code.
MAX_OPERATIONS = 9

# Defaults in job.params, overridden per module by the operation's own parameters.
SLOT_DEFAULTS = {"op_present": False, "operation": 0, "kind": "", "tool": 0, "tool_offset": 0,
                 "spindle_rpm": 0, "coolant": False, "feed": 0, "moves": []}
JOB_PARAMETERS = frozenset({
    "program_name", "program_number", "drawing", "units", "profile", "closed_by_axis", "stock_diameter",
    "stock_z_front", "stock_z_back", "tool_change_z", "tool_change_x", "clearance", "machine", "gear_class",
    "alternate", "template_version", *SLOT_DEFAULTS})
MODULE_PARAMETERS = {
    "prep": frozenset({"tool", "tool_offset", "op_present", "operation", "kind"}),
    "cutcond": frozenset({"spindle_rpm", "coolant", "op_present"}),
    "cutmotion": frozenset({"kind", "feed", "paths", "depth_per_pass", "infeed_angle", "thread_pitch",
                            "allowance", "op_present", "operation", "moves"}),
}


@register_model("turning")
class TurningModel:
    """Names the turning templates may use (for `engine lint`)."""

    def parameter_names(self, t: str, n: int) -> frozenset:
        return JOB_PARAMETERS | MODULE_PARAMETERS.get(t, frozenset())
