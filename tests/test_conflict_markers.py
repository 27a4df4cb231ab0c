"""No file of the project carries a git merge's conflict markers: a half-merged seed README once
shipped with both sides of a conflict in it, and nothing read it."""

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TEXT_SUFFIXES = {".md", ".py", ".csv", ".sql", ".toml", ".json", ".txt", ".cfg", ".html", ".yml"}
SKIPPED = {".git", ".venv", "venv", "node_modules", "build", "dist", "__pycache__"}
MARKERS = ("<<<<<<< ", ">>>>>>> ")


def project_text_files(root: Path) -> list[Path]:
    """Every text file of the project by its suffix, outside git's and the build's folders."""
    return [path for path in root.rglob("*")
            if path.suffix in TEXT_SUFFIXES and path.is_file()
            and not SKIPPED & set(path.relative_to(root).parts)]


def conflicted_lines(root: Path) -> list[str]:
    """`path:line` of each line that opens or closes a conflict."""
    return [f"{path.relative_to(root)}:{number}"
            for path in project_text_files(root)
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1)
            if line.startswith(MARKERS)]


def test_no_file_holds_a_merge_conflict():
    assert conflicted_lines(ROOT) == []


def test_the_check_finds_a_conflict_left_in_a_readme(tmp_path):
    (tmp_path / "seed").mkdir()
    (tmp_path / "seed" / "README.md").write_text("a\n<<<<<<< HEAD\nb\n=======\nc\n>>>>>>> 67cfa04 (x)\n")
    assert conflicted_lines(tmp_path) == ["seed/README.md:2", "seed/README.md:6"]
