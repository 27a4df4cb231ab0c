"""The documentation keeps up with the engine: the README stays an entrance (under 150 lines),
docs/cli.md is the CLI's own --help as it is now (scripts/cli_reference.py), every command is
explained in some page of the user guide (docs/guide/), every relative link leads to a file, and
every SQL example of the guide runs on the seeded database (rolled back, as the `conn` fixture
is), failing where its `-- expect error: <SQLSTATE or text>` comment says it fails."""
from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from typing import NamedTuple

import psycopg
import pytest

ROOT = Path(__file__).resolve().parent.parent
GUIDE = ROOT / "docs" / "guide"
README_MAX_LINES = 150   # an entrance a newcomer reads at once; the manual is docs/guide/
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
EXTERNAL = re.compile(r"^([a-z][a-z0-9+.-]*:|#)")   # https:, mailto:, a heading of the same page
SQL_BLOCK = re.compile(r"^```sql\n(.*?)^```", re.MULTILINE | re.DOTALL)
EXPECT_ERROR = re.compile(r"--\s*expect error:\s*(.+)")


def cli_reference():
    """scripts/cli_reference.py as a module (scripts/ is not a package: it is no part of the engine)."""
    spec = importlib.util.spec_from_file_location("cli_reference", ROOT / "scripts" / "cli_reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def guide_pages() -> list[Path]:
    return sorted(GUIDE.glob("*.md"))


def test_the_readme_is_under_150_lines():
    lines = len((ROOT / "README.md").read_text().splitlines())
    assert lines < README_MAX_LINES, f"README.md has {lines} lines; move the detail to docs/guide/"


def test_the_cli_reference_is_the_cli_help_as_it_is_now():
    reference = cli_reference()
    written = reference.OUTPUT.read_text() if reference.OUTPUT.is_file() else ""
    stale = reference.stale_commands(written, reference.render())
    assert not stale, f"docs/cli.md is stale ({', '.join(stale)}); run: python scripts/cli_reference.py"


def test_the_cli_reference_holds_every_command():
    paths = cli_reference().command_paths()
    assert {"engine", "engine instantiate", "engine template release", "engine db psql"} <= set(paths)
    headings = re.findall(r"^## (engine.*)$", (ROOT / "docs" / "cli.md").read_text(), re.MULTILINE)
    assert headings == paths


def test_every_command_is_explained_in_the_guide():
    text = "\n".join(page.read_text() for page in guide_pages())
    missing = [path for path in cli_reference().command_paths()
               if not re.search(re.escape(path) + r"(?![\w-])", text)]
    assert not missing, f"commands no page of docs/guide/ mentions: {', '.join(missing)}"


def markdown_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def broken_links(page: Path) -> list[str]:
    """The relative links of `page` whose file does not exist (an #anchor after it is not checked)."""
    targets = [target for target in LINK.findall(page.read_text()) if not EXTERNAL.match(target)]
    return [f"{page.relative_to(ROOT)}: {target}" for target in targets
            if not (page.parent / target.split("#", 1)[0]).exists()]


def test_every_relative_link_of_the_documentation_leads_to_a_file():
    broken = [link for page in markdown_files() for link in broken_links(page)]
    assert not broken, "links to nothing:\n" + "\n".join(broken)


class Example(NamedTuple):
    """One ```sql block of a guide page."""
    page: str
    line: int
    text: str


def sql_examples() -> list[Example]:
    return [Example(page.name, page.read_text()[:match.start()].count("\n") + 1, match[1])
            for page in guide_pages() for match in SQL_BLOCK.finditer(page.read_text())]


def test_the_guide_has_sql_examples_some_of_them_refused():
    examples = sql_examples()
    assert len(examples) >= 8 and any(EXPECT_ERROR.search(example.text) for example in examples)


def refused_as(error: psycopg.Error, expected: str) -> bool:
    """The error is the expected one: its SQLSTATE (5 characters), else its message contains the text."""
    if re.fullmatch(r"[0-9A-Z]{5}", expected):
        return error.sqlstate == expected
    return expected.lower() in str(error).lower()


@pytest.mark.parametrize("example", sql_examples(), ids=lambda example: f"{example.page}:{example.line}")
def test_the_sql_examples_of_the_guide_run_on_the_seeded_database(conn, example):
    expected = EXPECT_ERROR.search(example.text)
    if not expected:
        conn.execute(example.text)
        return
    with pytest.raises(psycopg.Error) as refused, conn.transaction():
        conn.execute(example.text)
    assert refused_as(refused.value, expected[1].strip()), f"{example.page}:{example.line}: {refused.value}"


LOOPBACK_ADDRESS = re.compile(r"(?:127\.0\.0\.1|localhost):(\d+)")


def test_the_web_view_s_addresses_in_the_documentation_use_its_default_port():
    """A reader copies the guide's curl line: its port must be the one `engine serve` listens on by
    default (8080; the review of issue 32 found 8000), unless the line gives --port itself.
    PostgreSQL's 5432 is no web address."""
    from engine.service.server import ServeOptions

    default = ServeOptions(database_url="").port
    pages = [ROOT / "README.md", *guide_pages(), ROOT / "docs" / "cli.md"]
    wrong = [f"{page.name}: {line.strip()}" for page in pages for line in page.read_text().splitlines()
             if "--port" not in line and "5432" not in line
             for port in LOOPBACK_ADDRESS.findall(line) if int(port) != default]
    assert not wrong
