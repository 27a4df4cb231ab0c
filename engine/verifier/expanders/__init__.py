"""The expanders of the dialects that have one (engine.verifier.expansion): each module registers
its function under the name its Dialect row gives. Importing the verifier imports them all, so a
dialect is never read without its expander; one whose expander is missing is refused."""
from . import (
    iso,  # noqa: F401  (registers the "iso" expander: Fanuc/Haas lathe programs)
    linuxcnc,  # noqa: F401  (registers the LinuxCNC lathe expander)
    sinumerik,  # noqa: F401  (the 840D lathe expander registers on import)
)
