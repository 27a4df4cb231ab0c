"""The repository stands alone (issue 16): a user who clones it has everything the README, the
documentation and the tests point at. No tracked file may point into a folder beside the
clone (the design notes and data once lived in a sibling folder) or into one machine's home or
work folders; the documentation those pointers meant is docs/, the real files the tests read
are tests/data, and each of those files names its origin and licence in a PROVENANCE.tsv."""
from __future__ import annotations

import csv
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
PROVENANCES = ("dxf", "nc")   # each folder of tests/data with its PROVENANCE.tsv

# Pointers out of the clone: the sibling folder of the old design notes, reference and data,
# and absolute paths into somebody's machine (system paths such as /etc or /proc are the
# machine's, not a checkout's, and stay allowed; so does /srv, where a shop keeps its NC files).
OUTSIDE = re.compile(rb"\.\./shared|\bshared/(DESIGN|reference|data|seeds|tools)\b"
                     rb"|(?<![\w.~-])/(work|home|root|Users|mnt)/")


def tracked_files() -> list[Path]:
    """The files of the checkout as git knows them (a clone has exactly these)."""
    listing = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [ROOT / name for name in listing.decode().split("\0") if name]


def provenance_rows() -> dict[Path, dict[str, str]]:
    """Every file a PROVENANCE.tsv lists → its row (repository, path, commit, licence)."""
    rows = {}
    for folder in PROVENANCES:
        with open(DATA / folder / "PROVENANCE.tsv", newline="") as table:
            for row in csv.reader(table, delimiter="\t"):
                if row[0].startswith("local_file"):
                    continue
                rows[DATA / folder / row[0]] = dict(zip(("file", "repo", "path", "commit"), row)) | {
                    "license": row[-1]}
    return rows


def test_no_tracked_file_points_outside_the_clone():
    others = set(provenance_rows())   # other people's files, byte for byte: not ours to edit
    found = []
    for path in tracked_files():
        if path in others or not path.is_file():
            continue
        for number, line in enumerate(path.read_bytes().split(b"\n"), 1):
            if OUTSIDE.search(line):
                found.append(f"{path.relative_to(ROOT)}:{number}: {line.decode(errors='replace').strip()}")
    assert not found, "pointers outside the clone (use docs/ or tests/data):\n" + "\n".join(found)


def test_every_data_file_is_listed_with_its_origin_and_licence():
    own = {DATA / "README.md"} | {DATA / folder / "PROVENANCE.tsv" for folder in PROVENANCES}
    files = {path for path in DATA.rglob("*") if path.is_file() and "__pycache__" not in path.parts}
    listed = provenance_rows()
    assert sorted(str(p.relative_to(DATA)) for p in files - own - set(listed)) == []
    assert sorted(str(p.relative_to(DATA)) for p in set(listed) - files) == []
    for path, row in listed.items():
        assert "/" in row["repo"] and re.fullmatch(r"[0-9a-f]{40}", row["commit"]), path
        assert re.match(r"(GPL|MIT|BSD|Apache|CC|LGPL|MPL)", row["license"]), path


def test_every_data_file_is_tracked():
    """A file the tests read but git ignores would be missing from every clone."""
    tracked = set(tracked_files())
    assert sorted(str(p.relative_to(ROOT)) for p in provenance_rows() if p not in tracked) == []


def test_the_documentation_the_code_points_at_is_there():
    for name in ("README.md", "design.md", "reference/hobbing.md"):
        assert (ROOT / "docs" / name).is_file(), name


# A section of the reference: §A5, §B, §B7, §C (the letters are the reference's alone; the
# paper's and the manuals' sections are numbers). A section of the design: "design notes §4".
REFERENCE_SECTION = re.compile(r"§([A-E])(\d*)(?![\w.])")
DESIGN_SECTION = re.compile(r"design(?: notes|\.md)? §(\d+)(?:[–-](\d+))?")


def reference_sections() -> set[str]:
    """A1…A7 and A, B and its numbered items B1…B15, C, D, E, as docs/reference/hobbing.md has them."""
    sections, part = set(), None
    for line in (ROOT / "docs" / "reference" / "hobbing.md").read_text().splitlines():
        if heading := re.match(r"##+ ([A-E])(\d*)\.", line):
            part = heading[1]
            sections.add(heading[1] + heading[2])
        elif (item := re.match(r"(\d+)\. \*\*", line)) and part == "B":
            sections.add(f"B{item[1]}")
    return sections


def cited(pattern: re.Pattern) -> list[tuple[str, tuple[str, ...]]]:
    """(file:line, groups) of every citation of `pattern` in the tracked files of the project."""
    others = set(provenance_rows())
    found = []
    for path in tracked_files():
        if path in others or path.suffix not in {".py", ".md", ".sql", ".csv", ".toml"}:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            found += [(f"{path.relative_to(ROOT)}:{number}", m.groups()) for m in pattern.finditer(line)]
    return found


def test_every_cited_section_of_the_reference_exists():
    sections = reference_sections()
    assert {"A1", "A5", "A7", "B", "B7", "B15", "C", "D", "E"} <= sections
    missing = [f"{where}: §{''.join(groups)}" for where, groups in cited(REFERENCE_SECTION)
               if "".join(groups) not in sections]
    assert missing == []


def test_every_cited_section_of_the_design_exists():
    text = (ROOT / "docs" / "design.md").read_text()
    sections = {int(n) for n in re.findall(r"^## (\d+)\. ", text, re.MULTILINE)}
    assert sections == set(range(1, 13))   # §11 delivery to the controls (issue 32), §12 plants (issue 33)
    missing = [f"{where}: §{'–'.join(g for g in groups if g)}" for where, groups in cited(DESIGN_SECTION)
               if not {int(g) for g in groups if g} <= sections]
    assert missing == []
