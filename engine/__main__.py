"""`python -m engine`: the command line, as the `engine` script runs it (the one module outside
engine/cli/ that imports it)."""
from .cli import main

main()
