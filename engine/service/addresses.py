"""Which addresses only this computer reaches (issue 32): `engine serve` asks for a login on any
other, and the open view takes a runner's request only when it was reached as one of these."""
from __future__ import annotations

import ipaddress

LOOPBACK_NAMES = {"localhost"}


def is_loopback(host: str) -> bool:
    """127.0.0.0/8, ::1 or localhost; a host name of another kind may resolve to any address."""
    if host.lower() in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
