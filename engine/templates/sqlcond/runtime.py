"""SQL_RUNTIME: every ``_sql_*`` helper a translated condition calls, by name."""

from __future__ import annotations

from collections.abc import Callable

from . import arithmetic, compare, logic, text
from .operands import _Deferred

_HELPER_MODULES = (logic, compare, text, arithmetic)
# Helpers that take operands after the first as thunks and force them themselves.
_LAZY = frozenset({"_sql_and", "_sql_or", "_sql_case", "_sql_coalesce"})


def _sql_defer(name, *args):
    fn, strict = _DEFERRABLE[name]
    return _Deferred(fn, args, strict)


def _own_helpers(module):
    """The ``_sql_*`` functions defined in `module` (not those it imports)."""
    return {
        name: value
        for name, value in vars(module).items()
        if name.startswith("_sql_") and callable(value) and value.__module__ == module.__name__
    }


SQL_RUNTIME: dict[str, Callable] = {
    "_sql_defer": _sql_defer,
    **{name: fn for module in _HELPER_MODULES for name, fn in _own_helpers(module).items()},
}

_DEFERRABLE = {
    name: (fn, name not in _LAZY) for name, fn in SQL_RUNTIME.items() if name != "_sql_defer"
}
