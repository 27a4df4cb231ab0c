"""Writing a picture (engine plot): PNG or SVG by the file's suffix, drawn off-screen (Agg), written
to a temporary file beside the target and renamed, so a failure leaves no half-written picture."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import EngineError

FORMATS = {".png": "png", ".svg": "svg"}
PNG_DPI = 150
TEMPORARY_PREFIX = ".plot-"


def plot_format(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise EngineError(f"cannot draw a plot as {path.name!r}: give -o FILE.png or FILE.svg")
    return FORMATS[suffix]


def picture_target(path) -> tuple[Path, str]:
    """The file to write and its format; EngineError for another suffix or a missing folder."""
    target = Path(path)
    file_format = plot_format(target)
    if not target.parent.is_dir():
        raise EngineError(f"folder {str(target.parent)!r} does not exist; create it or give -o "
                          "a file in an existing folder")
    return target, file_format


def literal(text: object) -> str:
    """Text from programs and records (a `; CUT` comment, a name, a drawing's file name) as it
    is written: matplotlib reads what stands between two `$` as TeX, which no shop's text means,
    and `\\$` is its escape for a dollar sign drawn as such. Every such text is drawn through this."""
    return str(text).replace("$", r"\$")


def new_figure(size_inches: tuple[float, float]):
    """A matplotlib Figure not tied to any screen (the engine runs on servers)."""
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(figsize=size_inches)


def save_atomically(figure, target: Path, file_format: str) -> None:
    """Write the picture whole or not at all; a folder that refuses the file (no write permission,
    /proc, a full disk) is the user's to fix: EngineError naming the file and the reason."""
    try:
        _write_then_rename(figure, target, file_format)
    except OSError as failure:
        raise EngineError(f"cannot write the picture {str(target)!r}: {reason(failure)}; "
                          "give -o a file in a folder you can write") from None


def reason(failure: OSError) -> str:
    """The system's words for the failure, on one line (a message is one line)."""
    return " ".join(str(failure.strerror or failure).split())


def _write_then_rename(figure, target: Path, file_format: str) -> None:
    # A short fixed prefix: the target's own name may use all 255 bytes a file name may have.
    handle, temporary = tempfile.mkstemp(prefix=TEMPORARY_PREFIX, suffix=target.suffix, dir=target.parent)
    os.close(handle)
    try:
        figure.savefig(temporary, format=file_format, dpi=PNG_DPI)
        os.chmod(temporary, 0o666 & ~current_umask())   # mkstemp makes it private
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def current_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
