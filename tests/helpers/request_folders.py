"""The request folders the tests of `engine serve`'s folder delivery answer (issue 32;
tests/test_serve_request_folder.py, the adversary's test_adversary32_folder_*.py): a fixture plugin."""
from __future__ import annotations

import pytest

from engine.programs.config import Config
from engine.service.request_folder import RequestFolder


@pytest.fixture
def folders(run, tmp_path):
    """The request folders of the 840D and the Fanuc under tmp_path/share, on the `run` database."""
    root = tmp_path / "share"
    root.mkdir()
    folder = RequestFolder(root, ["hobber-840d", "hobber-fanuc"], run.url, Config())
    yield folder
    folder.close()
