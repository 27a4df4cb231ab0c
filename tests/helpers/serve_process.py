"""`engine serve` as a shop runs it, a process of its own (tests/test_serve_web.py,
test_serve_command.py): started with its own runtime folder (its pid file) and no config file of
the user running the suite, on a port nobody listens on."""
from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parent.parent.parent


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def engine(*args: str, runtime: Path, env_extra: dict | None = None, **kwargs) -> subprocess.Popen:
    """`python -m engine ARGS` of this checkout, its output read as text."""
    environment = {**os.environ, "ENGINE_RUNTIME_DIR": str(runtime), "ENGINE_CONFIG": "",
                   "PYTHONPATH": str(REPOSITORY), **(env_extra or {})}
    environment.pop("DATABASE_URL", None)
    return subprocess.Popen([sys.executable, "-m", "engine", *args], env=environment, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kwargs)
