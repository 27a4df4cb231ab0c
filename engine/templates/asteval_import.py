"""asteval, imported without numpy. asteval imports numpy when it can (57 ms of every command's
start) though templates never use it (the interpreter runs with use_numpy=False): where numpy
is not loaded yet, asteval is imported as if numpy were not installed."""
from __future__ import annotations

import sys

if "asteval.asteval" not in sys.modules and "numpy" not in sys.modules:
    sys.modules["numpy"] = None   # type: ignore[assignment]  # None blocks an import (typeshed omits it); asteval's `import numpy` then fails: HAS_NUMPY is False
    try:
        import asteval.astutils
    finally:
        del sys.modules["numpy"]

import asteval  # noqa: E402  (imported above, or already by someone who had numpy loaded)
import asteval.astutils  # noqa: E402

Interpreter = asteval.Interpreter
ALL_NODES = tuple(asteval.asteval.ALL_NODES)
asteval_safe_pow = asteval.astutils.safe_pow
