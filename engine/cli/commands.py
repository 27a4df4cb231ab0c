"""The commands of `engine`, each imported when it is first looked up (issue 28: start-up).

`engine instantiate --gear 42` imports engine.cli.instantiate and none of the other command
modules (nor the library modules they import at their top); `engine --help` lists them with the
short help of engine.cli.short_help and imports none; a config file's table of a command and the
tests that walk the tree import the ones they name. A command gets
the conventions of engine.cli.conventions as it is imported, as it did when every command was
imported with engine.cli.app.
"""
from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator, MutableMapping

import click

# command name -> (module of engine.cli, the command's name in it); tests/test_cli.py checks
# that each loads a command of that name
COMMAND_MODULES = {
    "demo": ("db", "demo"), "db": ("db", "db"), "seed": ("db", "seed_command"),
    "gears": ("gears", "gears"), "classify": ("gears", "classify"),
    "instantiate": ("instantiate", "instantiate"), "explain": ("explain", "explain"),
    "template": ("templates", "template"), "lint": ("templates", "lint"), "hobs": ("hobs", "hobs"),
    "machines": ("machines", "machines"), "suggest": ("cases", "suggest"), "cases": ("cases", "cases"),
    "import-nc": ("nc_import", "import_nc_command"), "refactor": ("refactor", "refactor_command"),
    "import-dxf": ("turning", "import_dxf_command"), "plot": ("plot", "plot_command"),
    "simulate": ("simulate", "simulate"), "programs": ("programs", "programs"), "test": ("golden", "test_command"),
    "jobs": ("jobs", "jobs"), "config": ("settings", "config"), "fixtures": ("fixtures", "fixtures"),
    "materials": ("materials", "materials"), "serve": ("serve", "serve"), "plant": ("plant", "plant"),
}


class LazyCommands(MutableMapping):
    """A group's commands by name (click.Group.commands): a command named in `where` is imported
    on its first lookup, and `loaded(name, command)` runs on it once; a command added with
    add_command is kept as given. Membership, iteration and len read the names only."""

    def __init__(self, where: dict[str, tuple[str, str]], loaded: Callable[[str, click.Command], None]):
        self._where = dict(where)
        self._commands: dict[str, click.Command] = {}
        self._loaded = loaded

    def __getitem__(self, name: str) -> click.Command:
        if name not in self._commands:
            module, attribute = self._where[name]   # KeyError: no such command
            command = getattr(importlib.import_module(f"{__package__}.{module}"), attribute)
            self._loaded(name, command)
            self._commands[name] = command
        return self._commands[name]

    def __setitem__(self, name: str, command: click.Command) -> None:
        self._where.pop(name, None)
        self._commands[name] = command

    def __delitem__(self, name: str) -> None:
        if name not in self:
            raise KeyError(name)
        self._where.pop(name, None)
        self._commands.pop(name, None)

    def __contains__(self, name: object) -> bool:
        return name in self._where or name in self._commands

    def __iter__(self) -> Iterator[str]:
        return iter([*self._where, *(name for name in self._commands if name not in self._where)])

    def __len__(self) -> int:
        return len(set(self._where) | set(self._commands))

    def imported(self) -> set[str]:
        """The names whose commands are imported (or added) so far."""
        return set(self._commands)
