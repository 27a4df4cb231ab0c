"""Adversary of issue 32: the database URL's password is never shown. `engine serve` (and every
command) on a server that cannot be reached printed "cannot connect to postgresql://user:PASSWORD@…":
an error is printed on the shop's screen, logged, pasted into a ticket. The message still names the
server, the port and the user, so it says where it tried."""
import pytest
from click.testing import CliRunner

from engine.cli import main

URLS = ["postgresql://shop:hunter2-secret@127.0.0.1:1/engine",
        "postgresql://shop@127.0.0.1:1/engine?password=hunter2-secret",
        "host=127.0.0.1 port=1 user=shop password=hunter2-secret dbname=engine"]


@pytest.mark.parametrize("url", URLS)
@pytest.mark.parametrize("command", [["db", "status"], ["serve", "--port", "18761"]])
def test_a_connection_failure_names_the_server_never_the_password(url, command):
    result = CliRunner().invoke(main, ["--database-url", url, *command])
    assert result.exit_code == 1 and len(result.stderr.strip().splitlines()) == 1, result.output
    assert "hunter2" not in result.output and "cannot connect to" in result.stderr
    assert "127.0.0.1" in result.stderr and "shop" in result.stderr and "1" in result.stderr
