"""Every hobbing model, registered with engine.gears.models as its module is imported: the
programs, release and command-line code that asks for a model imports this module first."""
from . import crowned, cylindrical, duplex, taper, worm_wheel  # noqa: F401  (each registers its model)
