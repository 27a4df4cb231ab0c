"""What every command of `engine` has without declaring it (issue 16, "Conventions people expect"):

* an environment variable per option, ENGINE_<COMMAND>_<OPTION> (ENGINE_INSTANTIATE_MACHINE,
  ENGINE_HOBS_MATCH_SHIFT_TRAVEL, ENGINE_REFACTOR_JSON=1), after the variables it already had
  (DATABASE_URL before ENGINE_DATABASE_URL);
* defaults of its options from the config file (engine.programs.config; click's default_map);
* except the options of COMMAND_LINE_ONLY, which confirm what cannot be undone: no variable,
  and refused in the config file;
* an `Example:` line at the end of its --help (engine.cli.examples, or its own docstring's);
* --json remembered, so that an error of a --json invocation is reported as JSON.

Applied to `engine` itself when engine.cli.app is imported, and to each of its commands (with
every command below it) as the command is imported (engine.cli.commands), so a command added to
any group gets them too.
"""
from __future__ import annotations

import click

from ..programs.config import Config, config_error
from .examples import EXAMPLES

# read by the engine itself, never generated for an option (test_cli_conventions checks it)
RESERVED_ENVVARS = frozenset({"ENGINE_CONFIG", "ENGINE_DATA_DIR", "ENGINE_RUNTIME_DIR", "ENGINE_TEST_SERVERS"})
MACHINE_DEFAULT_FOR = ("instantiate", "suggest")   # the commands the config's `machine` is the default of
JSON_SEEN = "engine.json"   # ctx.meta: the invoked command's --json is on (command line, environment or config)

DELETE = "it confirms a delete, which cannot be undone"
COMMAND_LINE_ONLY = {   # (command path, option): why it is typed on each invocation, never a default
    ("engine gears delete", "yes"): DELETE,
    ("engine jobs delete", "yes"): DELETE,
    ("engine hobs delete", "yes"): DELETE,
    ("engine template release", "yes"): "it releases a draft to the shop floor without asking",
    ("engine template release", "without-golden-tests"): "it releases a class no golden test checks",
    ("engine gears import", "replace"): "it overwrites stored gears",
    ("engine hobs import", "replace"): "it replaces stored hobs whole",
    ("engine fixtures import", "replace"): "it replaces stored work-holdings whole",
    ("engine materials import", "replace"): "it replaces stored materials whole",
    ("engine cases import", "replace"): "it overwrites stored cases of the machining history",
    ("engine instantiate", "force"): "it replaces program files in --out, which a machine may be loading",
    ("engine db backup", "force"): "it replaces a backup file, which may be the only one",
    ("engine instantiate", "skip-bad"): "it stores a batch without its bad gears",
    ("engine instantiate", "draft"): "it makes programs of a draft that has not passed the release gate",
    # what instantiate makes programs of: a default would store programs (records nobody deletes)
    # for every gear, or refuse the gear the user typed
    **{("engine instantiate", selector): "it chooses what programs are made and stored"
       for selector in ("gear", "job", "class", "gears", "jobs", "all")},
    ("engine instantiate", "unverified"): "it stores a program no verifier read",
    ("engine seed", "samples"): "it loads sample gears, hobs and cases, which a shop's database must not get unasked",
}


def walk(command: click.Command, path: str = "engine"):
    """(command path, command) of `command` and every command below it."""
    yield path, command
    for name, sub in getattr(command, "commands", {}).items():
        yield from walk(sub, f"{path} {name}")


def options(command: click.Command) -> list[click.Option]:
    """The options that give the command a value (not --help, --version: a variable ENGINE_VERSION
    set for another purpose must not turn every command into printing the version)."""
    return [param for param in command.params
            if isinstance(param, click.Option) and param.expose_value and param.opts[0].startswith("-")]


def option_name(option: click.Option) -> str:
    """The option as users know it: its longest flag without dashes (--shift-y: shift-y)."""
    return max(option.opts, key=len).lstrip("-")


def envvar_name(path: str, option: click.Option) -> str:
    """ENGINE_ and the command path after `engine` and the option, upper case, - as _."""
    words = ["ENGINE", *path.split()[1:], option_name(option)]
    return "_".join(words).upper().replace("-", "_")


def apply_conventions(command: click.Command, path: str = "engine") -> None:
    """The conventions given to `command` (at `path`) and every command below it."""
    for path_below, below in walk(command, path):
        apply_to_one(path_below, below)


def apply_to_one(path: str, command: click.Command) -> None:
    """The conventions given to `command` alone, not to the commands of a group (engine's own
    are given as each is imported: engine.cli.commands)."""
    _add_example(path, command)
    for option in options(command):
        _add_envvar(path, option)
        _remember_json(option)


def command_line_only(path: str, option: click.Option) -> str | None:
    """Why the option must be typed on the command line (COMMAND_LINE_ONLY), else None."""
    return COMMAND_LINE_ONLY.get((path, option_name(option)))


def _add_example(path: str, command: click.Command) -> None:
    """The docstring's own `Example:` lines, else the table's, as the help's last paragraph
    (\\b keeps click from rewrapping it into the text before)."""
    lines = (command.help or "").splitlines()
    own = [line.strip() for line in lines if line.strip().startswith("Example:")]
    if own:
        command.help = "\n".join(line for line in lines if not line.strip().startswith("Example:")).rstrip()
    examples = own or ([f"Example: {EXAMPLES[path]}"] if path in EXAMPLES else [])
    if examples:
        command.epilog = "\n\n".join(filter(None, [command.epilog, "\b\n" + "\n".join(examples)]))


def _add_envvar(path: str, option: click.Option) -> None:
    name = envvar_name(path, option)
    if command_line_only(path, option):
        option.allow_from_autoenv = False   # nor a variable of click's own
        return
    if name in RESERVED_ENVVARS:
        return
    existing = [option.envvar] if isinstance(option.envvar, str) else list(option.envvar or [])
    option.envvar = [*existing, name] if name not in existing else existing


def _remember_json(option: click.Option) -> None:
    if "--json" not in option.opts:
        return
    previous = option.callback

    def remember(ctx, param, value):
        ctx.meta[JSON_SEEN] = ctx.meta.get(JSON_SEEN) or bool(value)
        return previous(ctx, param, value) if previous else value
    option.callback = remember


def default_map(group: click.Group, config: Config) -> dict:
    """The config's option defaults as click's default_map: per command path (tables, e.g.
    [instantiate], [hobs.match]) option names as on the command line (- or _) mapped to the
    parameters; the config's `machine` is the default --machine of MACHINE_DEFAULT_FOR. An
    unknown command or option is refused naming the file and its line."""
    defaults = _defaults(group, "engine", config.commands, config)
    for name in MACHINE_DEFAULT_FOR if config.machine else ():
        defaults.setdefault(name, {}).setdefault("machine", config.machine)
    return defaults


def _defaults(command: click.Command, path: str, table: dict, config: Config) -> dict:
    subcommands = getattr(command, "commands", {})
    names = {spelling: option for option in options(command)
             for spelling in (option_name(option), option_name(option).replace("-", "_"), option.name)}
    result = {}
    for key, value in table.items():
        if isinstance(value, dict) and key in subcommands:
            result[key] = _defaults(subcommands[key], f"{path} {key}", value, config)
        elif key in names and not isinstance(value, dict):
            _refuse_command_line_only(config, path, key, names[key])
            result[names[key].name] = value
        else:
            raise config_error(config, key, _unknown(path, key, command))
    return result


def _refuse_command_line_only(config: Config, path: str, key: str, option: click.Option) -> None:
    reason = command_line_only(path, option)
    if reason:
        raise config_error(config, key, f"--{option_name(option)} of `{path}` is given on the command line only "
                                        f"({reason}); remove it from the file")


def json_from_defaults(ctx: click.Context) -> bool:
    """The command's --json is on by its environment variable or the config file: known even when
    its options could not be parsed (a usage error), so that error is JSON too."""
    option = next((option for option in options(ctx.command) if "--json" in option.opts), None)
    if option is None:
        return False
    value, _source = option.consume_value(ctx, {})
    try:
        return bool(option.type_cast_value(ctx, value))
    except click.BadParameter:   # a variable like ENGINE_LINT_JSON=maybe: its own error says so
        return False


def _unknown(path: str, key: str, command: click.Command) -> str:
    known = sorted(option_name(option) for option in options(command))
    subcommands = getattr(command, "commands", {})
    commands = f"; its commands: {', '.join(sorted(subcommands))}" if subcommands else ""
    return (f"`{path}` has no option --{key.replace('_', '-')} (its options: {', '.join(known) or 'none'}"
            f"{commands}); see `{path} --help`")
