"""`engine config path|show`: where the config file is, and what it sets (engine.programs.config)."""
from __future__ import annotations

import click

from .context import emit_json, settings


@click.group("config")
def config():
    """The config file: option defaults, the default machine, output folder and line endings per
    machine (docs/guide/configuration.md). Command line and ENGINE_* variables win over it."""


@config.command("path")
def config_path_command():
    """Print the config file's path (ENGINE_CONFIG, else the user's config directory), and on
    stderr whether it exists."""
    from ..programs.config import config_path

    path = config_path()
    click.echo(str(path) if path else "")
    click.echo("(ENGINE_CONFIG is empty: no config file)" if path is None else
               "(exists)" if path.exists() else "(not there: the built-in defaults apply)", err=True)


@config.command("show")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: path, machine, line_endings, "
              "machines, defaults.")
@click.pass_context
def config_show(ctx, as_json):
    """Print what the config file sets: the default machine, line endings, each machine's output
    folder and the option defaults of each command, as the engine read them."""
    config = settings(ctx)
    defaults = ctx.find_root().default_map or {}
    shown = {"path": str(config.path) if config.path else None, "machine": config.machine,
             "line_endings": config.line_endings, "machines": config.machines, "defaults": defaults}
    if as_json:
        return emit_json(shown)
    click.echo(f"# {shown['path'] or 'no config file'}")
    for key in ("machine", "line_endings"):
        click.echo(f"{key} = {shown[key]!r}" if shown[key] is not None else f"# {key}: not set")
    for name, entry in config.machines.items():
        click.echo(f"[machines.{name}] " + ", ".join(f"{key} = {value!r}" for key, value in entry.items()))
    for path, values in _flat(defaults):
        click.echo(f"[{path}] " + ", ".join(f"{key} = {value!r}" for key, value in values.items()))


def _flat(defaults: dict, path: str = ""):
    """(command path, its option defaults) of the nested default_map."""
    own = {key: value for key, value in defaults.items() if not isinstance(value, dict)}
    if own and path:
        yield path, own
    for key, value in defaults.items():
        if isinstance(value, dict):
            yield from _flat(value, f"{path}.{key}" if path else key)
