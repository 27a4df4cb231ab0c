"""Writing .MPF files: nothing half-written. Files are written next to their target under a
temporary name and renamed only when the database transaction has committed."""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from ..errors import EngineError


def target_paths(names: list[str], out: str | Path) -> dict[str, Path]:
    """One program: `out` is the file (or an existing directory); several: `out` is a directory."""
    out = Path(out)
    if len(names) == 1 and not out.is_dir():
        return {names[0]: out}
    if out.exists() and not out.is_dir():
        raise EngineError(f"--out {out} is a file; give a directory for a batch of programs")
    twice = sorted({name for name in names if names.count(name) > 1}) if len(set(names)) < len(names) else []
    if twice:   # one file would silently replace the other (jobs of one gear made again, say)
        raise EngineError(f"{len(names) - len(set(names)) + 1} programs of this batch are named {twice[0]}, so "
                          f"their files would replace each other in {out}; make them without --out, or one at a time")
    return {name: out / f"{name}.MPF" for name in names}


@contextlib.contextmanager
def write_program_files(planned, out):
    """Yield {program name: final path}; files appear only if the block succeeds."""
    if out is None:
        yield {}
        return
    paths = target_paths([item.name for item in planned], out)
    temporary = {}
    try:
        for item in planned:
            temporary[item.name] = _write_temporary(paths[item.name], item.lines)
        yield {name: str(path) for name, path in paths.items()}
        for name, temp_path in temporary.items():
            os.replace(temp_path, paths[name])
    finally:
        for temp_path in temporary.values():
            with contextlib.suppress(FileNotFoundError):
                os.unlink(temp_path)


def _write_temporary(path: Path, lines: list[str]) -> str:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temp_path = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
        with os.fdopen(handle, "w", encoding="ascii", newline="\n") as file:
            file.write("\n".join(lines) + "\n")
    except OSError as error:
        raise EngineError(f"cannot write {path}: {error.strerror}") from None
    except UnicodeEncodeError:
        raise EngineError(f"program for {path.name} has non-ASCII characters; the control reads ASCII") from None
    return temp_path
