"""Load a DXF file tolerantly and say what had to be repaired.

The strict reader (`ezdxf.readfile`) is tried first because it is about 1.7x faster than
`ezdxf.recover` on large files; when it fails, `ezdxf.recover` rebuilds what it can. In
both cases the auditor runs and its fixes are reported. Files that are not ASCII DXF at
all (DWG, other text, ASCII or binary DXF cut off before EOF) are refused before any parsing,
with one line that says what the file is and what to do.
"""
from __future__ import annotations

import contextlib
import logging
import re
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

if TYPE_CHECKING:   # ezdxf takes a third of a second to import: only reading a drawing pays it
    from ezdxf.document import Drawing as EzdxfDocument

from ..errors import EngineError

BINARY_SENTINEL = b"AutoCAD Binary DXF"
BINARY_EOF = b"\x00EOF\x00"   # the value of the last group (code 0), NUL-terminated
DWG_MAGIC = re.compile(rb"^AC10\d\d")
UTF8_BOM = b"\xef\xbb\xbf"
HEAD_BYTES = 4096
TAIL_BYTES = 256
# Trailing bytes some writers put after EOF: DOS end-of-file (Ctrl-Z), NUL, whitespace.
TRAILING_JUNK = b" \t\r\n\x1a\x00"


class DxfError(EngineError):
    """A drawing that cannot become a job; the message names the file, layer, handle or text."""


class DrawingFile(msgspec.Struct):
    """An opened drawing: the ezdxf document and what the reader repaired or assumed."""
    path: Path
    doc: EzdxfDocument
    repairs: list[str] = []


def load_drawing_file(path: str | Path) -> DrawingFile:
    """Open PATH as an ASCII or binary DXF; refuse DWG, non-DXF and truncated files."""
    path = Path(path)
    check_is_ascii_dxf(path)
    repairs: list[str] = []
    try:
        import ezdxf

        doc = ezdxf.readfile(path)
    except Exception as strict_failure:  # any strict-reader failure: the tolerant reader decides
        doc = recover_document(path)
        repairs.append(f"strict reading failed ({one_line(strict_failure)}); read with ezdxf.recover")
    repairs.extend(audit_messages(doc))
    return DrawingFile(path, doc, repairs)


def recover_document(path: Path) -> EzdxfDocument:
    """ezdxf.recover rebuilds sections, tables and links; a file whose group codes and values
    are out of step is refused (its explore mode would guess, and a guessed coordinate
    makes a wrong part)."""
    try:
        from ezdxf import recover

        doc, _ = recover.readfile(path)
    except Exception as failure:  # ezdxf raises several types for unreadable structure
        raise DxfError(f"{path}: not a readable DXF ({one_line(failure)}); "
                       "save it again as DXF from the CAD program") from None
    return doc


def audit_messages(doc: EzdxfDocument) -> list[str]:
    auditor = doc.audit()
    return ([f"fixed: {entry.message}" for entry in auditor.fixes]
            + [f"error: {entry.message}" for entry in auditor.errors])


def check_is_ascii_dxf(path: Path) -> None:
    """Refuse, by looking at the first and last bytes only, what ezdxf should not parse.
    Binary DXF (ezdxf reads it) only has to end with its EOF tag."""
    if not path.is_file():
        raise DxfError(f"{path}: no such file")
    size = path.stat().st_size
    with path.open("rb") as stream:
        head = stream.read(HEAD_BYTES)
        stream.seek(max(0, size - TAIL_BYTES))
        tail = stream.read()
    if head.startswith(BINARY_SENTINEL):
        return check_binary_end(path, tail, size)
    if DWG_MAGIC.match(head):
        raise DxfError(f"{path}: this is a DWG file, not DXF; export it as ASCII DXF")
    if first_tag(head) != ("0", "SECTION"):
        raise DxfError(f"{path}: not a DXF file (it does not start with a SECTION); "
                       "export the drawing as ASCII DXF")
    if not ends_with_eof(tail):
        raise DxfError(f"{path}: truncated DXF (no '0 / EOF' at the end, {size} bytes); "
                       "copy or export the file again")


def check_binary_end(path: Path, tail: bytes, size: int) -> None:
    """A binary DXF ends with group code 0 and the string 'EOF' and its NUL terminator; a
    copy cut off before it lost entities ezdxf would not notice are missing."""
    if not tail.rstrip(b"\x1a").endswith(BINARY_EOF):
        raise DxfError(f"{path}: truncated binary DXF (no EOF tag at the end, {size} bytes); "
                       "copy or export the file again")


def first_tag(head: bytes) -> tuple[str, str] | None:
    """The first (group code, value) pair, skipping 999 comments; None if there is none."""
    lines = head.removeprefix(UTF8_BOM).decode("latin-1").splitlines()
    for index in range(0, len(lines) - 1, 2):
        code, value = lines[index].strip(), lines[index + 1].strip()
        if code != "999":
            return code, value
    return None


def ends_with_eof(tail: bytes) -> bool:
    lines = tail.rstrip(TRAILING_JUNK).decode("latin-1").splitlines()
    return len(lines) >= 2 and lines[-1].strip() == "EOF" and lines[-2].strip() == "0"


def one_line(error: Exception) -> str:
    text = " ".join(str(error).split()) or type(error).__name__
    return f"{type(error).__name__}: {text}" if not isinstance(error, DxfError) else text


class _Collector(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


@contextlib.contextmanager
def ezdxf_warnings():
    """Collect what ezdxf logs (e.g. while exploding blocks) instead of printing it; yields
    the list of messages, filled when the block ends."""
    logger, collector = logging.getLogger("ezdxf"), _Collector()
    propagate = logger.propagate
    logger.addHandler(collector)
    logger.propagate = False
    try:
        yield collector.messages
    finally:
        logger.removeHandler(collector)
        logger.propagate = propagate


def summarised(messages: list[str], limit: int = 3) -> list[str]:
    """Distinct messages with their counts, the most frequent first."""
    counts: dict[str, int] = {}
    for message in messages:
        counts[message] = counts.get(message, 0) + 1
    ranked = sorted(counts.items(), key=lambda item: -item[1])
    lines = [f"ezdxf: {message}" + (f" ({count}x)" if count > 1 else "") for message, count in ranked[:limit]]
    if len(ranked) > limit:
        lines.append(f"ezdxf: {len(ranked) - limit} more distinct warning(s)")
    return lines
