"""The shop's settings file: defaults of command options, the default machine, the output folder
and line endings per machine (docs/guide/configuration.md).

A TOML file in the user's config directory (platformdirs: ~/.config/nc-template-engine/config.toml
on Linux), or the file ENGINE_CONFIG names (ENGINE_CONFIG="" reads none). Its values are only
defaults: the command line and the environment (ENGINE_<COMMAND>_<OPTION>) win over them. A
malformed file is refused naming the file and the line, so a typo never silently changes where
programs go.

    line_endings = "crlf"            # program files written with CR LF (the stored lines never change)
    machine = "hobber-840d"          # the default machine of instantiate and suggest

    [instantiate]                    # defaults of any command's options, by option name
    cuts = 2

    [machines.hobber-840d]
    out = "/srv/nc/hobber"           # instantiate writes here when --out is not given
    line_endings = "lf"              # this machine's files: LF, whatever the file-wide setting
    ftp_secret_env = "HOBBER_SECRET" # engine serve: the variable holding the machine's FTP secret

A program file is written with its class's layout (LF and a final newline, or what the file an
imported class came from had: engine.nc.layout). A line ending set here overrides only the
line ending, for the files of the machine it is set for (its table's, else the file-wide one); the
final newline stays the class's. Unset, the class decides: a CRLF program imported from a file
comes back CRLF.
"""
from __future__ import annotations

import os
import re
import stat
import sys
from pathlib import Path

import msgspec

from ..errors import EngineError
from ..machines.records import DEFAULT_HOBBING_MACHINE
from ..nc.layout import ENDING_NAMES

APP = "nc-template-engine"
LINE_ENDINGS = {name: ending for ending, name in ENDING_NAMES.items()}   # "lf": "\n", "crlf": "\r\n"
SETTINGS = ("machine", "line_endings", "machines")   # top-level keys that are not command options
MAX_CONFIG_BYTES = 1 << 20   # a settings file is a few hundred bytes; a bound, not a limit anyone meets
MACHINE_SETTINGS = ("out", "line_endings", "ftp_secret_env")
# A machine's FTP secret (engine serve, issue 32) is named, never written here: a config file is read by
# others (a shared folder, a backup), so a secret in it is refused naming the variable to use instead.
SECRET_KEYS = ("ftp_secret", "ftp_password", "secret", "password")
ENVIRONMENT_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


class Config(msgspec.Struct, frozen=True):
    """The settings of the config file: option defaults by command, the default machine, line endings and output
    folders."""
    path: Path | None = None
    commands: dict = {}   # everything that is not a setting: option defaults
    machine: str | None = None
    line_endings: str | None = None   # None: each class's own (engine.nc.layout)
    machines: dict = {}   # machine name -> {out, line_endings}
    text: str = ""


def config_path() -> Path | None:
    """ENGINE_CONFIG if set (empty: no file), else config.toml in the user's config directory."""
    if "ENGINE_CONFIG" in os.environ:
        return Path(os.environ["ENGINE_CONFIG"]) if os.environ["ENGINE_CONFIG"] else None
    import platformdirs

    return Path(platformdirs.user_config_dir(APP)) / "config.toml"


def load_config(path: Path | None = None, named: bool | None = None) -> Config:
    """The settings of `path` (default config_path()). A missing default file is no settings; a
    missing file that ENGINE_CONFIG names, or a malformed one, is an EngineError naming it."""
    path = config_path() if path is None else path
    named = "ENGINE_CONFIG" in os.environ if named is None else named
    if path is None or (not path.exists() and not named):
        return Config()
    text = _read(path)
    tomllib = _toml_reader()
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise EngineError(f"config file {path}: {error}; fix that line") from None
    return _settings(path, text, data)


def _toml_reader():
    """The TOML reader, imported only when there is a file to read (issue 28: start-up)."""
    if sys.version_info >= (3, 11):
        import tomllib
    else:   # Python 3.10
        import tomli as tomllib
    return tomllib


def _read(path: Path) -> str:
    """The file's text; only a regular file of at most MAX_CONFIG_BYTES (issue 26: /dev/zero was
    read until memory ran out, a FIFO waited for a writer forever). It is opened without waiting
    (O_NONBLOCK: a FIFO opens at once) and what was opened is checked before a byte is read."""
    try:
        with open(os.open(path, os.O_RDONLY | os.O_NONBLOCK), "rb") as file:
            if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
                raise EngineError(f"config file {path}: is not a regular file (a device, pipe or folder); "
                                  "point ENGINE_CONFIG at a TOML file")
            data = file.read(MAX_CONFIG_BYTES + 1)
        if len(data) > MAX_CONFIG_BYTES:
            raise EngineError(f"config file {path}: is larger than {MAX_CONFIG_BYTES >> 10} KiB, more than any "
                              "settings need; point ENGINE_CONFIG at the TOML file of the settings")
        return data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise EngineError(f"config file {path}: cannot be read ({reason}); fix it or set ENGINE_CONFIG") from None


def _settings(path: Path, text: str, data: dict) -> Config:
    machines = data.get("machines", {})
    config = Config(path, {key: value for key, value in data.items() if key not in SETTINGS},
                    data.get("machine"), data.get("line_endings"), machines, text)
    if config.machine is not None and not isinstance(config.machine, str):
        raise config_error(config, "machine", "give a machine name in quotes, e.g. \"hobber-840d\"")
    _check_line_endings(config, config.line_endings)
    if not isinstance(machines, dict) or not all(isinstance(entry, dict) for entry in machines.values()):
        raise config_error(config, "machines", "give a table per machine: [machines.hobber-840d] out = \"/srv/nc\"")
    for entry in machines.values():
        _check_machine(config, entry)
    return config


def _check_machine(config: Config, entry: dict) -> None:
    for key, value in entry.items():
        if key in SECRET_KEYS:
            raise config_error(config, key, "a secret is never kept in the config file (others can read it): put "
                                            "it in an environment variable and name that with ftp_secret_env")
        if key not in MACHINE_SETTINGS:
            raise config_error(config, key, f"a machine's table takes {', '.join(MACHINE_SETTINGS)}")
        if not isinstance(value, str):
            raise config_error(config, key, "give the value in quotes")
    _check_line_endings(config, entry.get("line_endings"))
    if "ftp_secret_env" in entry and not ENVIRONMENT_NAME.fullmatch(entry["ftp_secret_env"]):
        raise config_error(config, "ftp_secret_env", "give the name of an environment variable, e.g. "
                                                     "\"HOBBER_SECRET\"")


def _check_line_endings(config: Config, value) -> None:
    if value is not None and value not in LINE_ENDINGS:
        raise config_error(config, "line_endings", f"{value!r} is not one of {', '.join(map(repr, LINE_ENDINGS))}")


def config_error(config: Config, key: str, advice: str) -> EngineError:
    """A value the file holds that the engine cannot use: the file, the key's line and what to do."""
    return EngineError(f"config file {config.path}, line {key_line(config.text, key)}: {key}: {advice}")


def key_line(text: str, key: str) -> int | str:
    """The first line that sets `key` (TOML parsers give no positions of valid values)."""
    pattern = re.compile(rf"^\s*(\[\s*)?[\"']?{re.escape(key)}\b", re.MULTILINE)
    match = pattern.search(text)
    return text.count("\n", 0, match.start()) + 1 if match else "?"


def output_folder(config: Config, machine: str | None, out: str | None) -> str | None:
    """Where instantiate writes programs: --out if given, else the machine's folder of the config
    (ending in the separator, so one program goes into it too), else nowhere (printed)."""
    folder = config.machines.get(machine or config.machine or DEFAULT_HOBBING_MACHINE, {}).get("out")
    if out is not None or folder is None:
        return out
    return os.path.join(os.path.expanduser(folder), "")


def line_ending(config: Config, machine: str | None = None) -> str | None:
    """The line ending the file sets for the machine's program files: the machine's table's, else
    the file-wide one; None when neither is set (each program's class decides)."""
    entry = config.machines.get(machine or config.machine or DEFAULT_HOBBING_MACHINE, {})
    name = entry.get("line_endings", config.line_endings)
    return None if name is None else LINE_ENDINGS[name]
