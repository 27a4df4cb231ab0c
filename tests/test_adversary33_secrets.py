"""Issue 33's adversary: a head office's URL carries its password (`engine plant subscribe --head
postgresql://engine:PASSWORD@head/engine`); no message may print it, whether the server is
unreachable or the URL malformed, and a malformed URL is bad input (exit 1), not a bug (exit 2)."""
from __future__ import annotations

import pytest
from click.testing import CliRunner

from engine.cli.app import main

SECRET = "Kx7-s3cr%ZZet"   # %ZZ: not a percent-encoding, so libpq quotes the token in its message


@pytest.mark.parametrize("url", [f"postgresql://engine:{SECRET.replace('%ZZ', '')}@127.0.0.1:1/none",
                                 f"postgresql://engine:{SECRET}@127.0.0.1:1/none",
                                 f"postgresql://engine@127.0.0.1:1/none?password={SECRET.replace('%ZZ', '')}",
                                 f"host=127.0.0.1 port=1 user=engine password={SECRET.replace('%ZZ', '')} dbname=x",
                                 f"host=127.0.0.1 port=1 password='{SECRET}' sslmode=bogus"])
def test_no_message_prints_the_password_of_a_url(url):
    result = CliRunner().invoke(main, ["--database-url", url, "db", "status"])
    assert result.exit_code == 1 and result.stderr.count("\n") == 1
    assert result.stderr.startswith("error: cannot connect to ")
    assert "Kx7" not in result.stderr and "***" in result.stderr
