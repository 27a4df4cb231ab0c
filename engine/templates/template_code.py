"""A whole template compiled into one code object, so an instantiation is one `exec`
instead of one `eval` per expression (the way Jinja2 compiles a template).

The generated code is built as an AST from the already checked and guarded expressions
(never from source text). Each expression gets its own line number, so a failure maps
back to its row, column and text through the traceback. Scope = job parameters ∪
parameters of module (T, N) ∪ intermediate variables, intermediates winning, then module
parameters: `_enter` switches module parameters in and out when the module changes.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass


DEADLINE_CHECK_ROWS = 50   # rows between two looks at the clock


@dataclass(frozen=True)
class Place:
    row_id: int
    column: str
    text: str


class _Builder:
    def __init__(self):
        self.places: list[Place] = [Place(-1, "", "")]   # line numbers start at 1

    def place(self, node: ast.AST, row_id: int, column: str, text: str) -> ast.AST:
        self.places.append(Place(row_id, column, text))
        line = len(self.places) - 1
        for child in ast.walk(node):
            if "lineno" in child._attributes:
                child.lineno = child.end_lineno = line
                child.col_offset = child.end_col_offset = 0
        return node


def _call(function: str, *args: ast.expr) -> ast.Call:
    return ast.Call(ast.Name(function, ast.Load()), list(args), [])


def _statement(expression: ast.expr) -> ast.Expr:
    return ast.Expr(expression)


def build(compiled_rows, gear_class: str):
    """Code object of the whole template, and the table of line number → Place."""
    builder, body, module = _Builder(), [], None
    for number, row in enumerate(compiled_rows):
        if number % DEADLINE_CHECK_ROWS == 0:
            body.append(builder.place(_deadline_check(), row.row.id, "o", ""))
        if row.module != module:
            module = row.module
            body.append(builder.place(_module_entry(f"{module[0]}:{module[1]}"), row.row.id, "o", ""))
        body.extend(_row_code(builder, row))
    tree = ast.fix_missing_locations(ast.Module(body=body, type_ignores=[]))
    return compile(tree, f"<template {gear_class}>", "exec"), tuple(builder.places)


def _deadline_check() -> ast.If:
    """`if _clock() > _deadline: _timeout()`"""
    test = ast.Compare(_call("_clock"), [ast.Gt()], [ast.Name("_deadline", ast.Load())])
    return ast.If(test, [_statement(_call("_timeout"))], [])


def _module_entry(key: str) -> ast.If:
    """`if _prev or key in _mp: _enter(key)` — switch parameters only where some apply."""
    test = ast.BoolOp(ast.Or(), [ast.Name("_prev", ast.Load()),
                                 ast.Compare(ast.Constant(key), [ast.In()], [ast.Name("_mp", ast.Load())])])
    return ast.If(test, [_statement(_call("_enter", ast.Constant(key)))], [])


def _row_code(builder: _Builder, row) -> list[ast.stmt]:
    row_id, statements = row.row.id, []
    for name, expression in row.s:
        target = [ast.Subscript(ast.Name("_i", ast.Load()), ast.Constant(name), ast.Store()),
                  ast.Name(name, ast.Store())]
        statements.append(builder.place(ast.Assign(target, expression.tree), row_id, "s", expression.text))
    statements += _output_code(builder, row)
    if row.s and row.p_calc is not None:
        test = builder.place(row.p_calc.tree, row_id, "p_calc", row.p_calc.text)
        return [ast.If(test, statements, [])] if statements else []
    return statements


def _output_code(builder: _Builder, row) -> list[ast.stmt]:
    if row.o is None:
        return []
    row_id = row.row.id
    text = builder.place(_text_of(row.o.tree), row_id, "o", row.o.text)
    assign = ast.Assign([ast.Name("_o", ast.Store())], text)
    emit = [builder.place(_statement(_call("_lines_append", ast.Name("_o", ast.Load()))), row_id, "o", row.o.text),
            builder.place(_statement(_call("_rows_append", ast.Constant(row_id))), row_id, "o", row.o.text)]
    if row.p_emit is None:
        return [assign, *emit]
    test = builder.place(row.p_emit.tree, row_id, "p_emit", row.p_emit.text)
    return [assign, ast.If(test, emit, [])]


def _text_of(tree: ast.expr) -> ast.expr:
    """A literal or an f-string is text by construction (its parts are bounded by the guards
    and by what is stored); anything else goes through `_text`, which checks."""
    if isinstance(tree, ast.Constant) and isinstance(tree.value, str):
        return tree
    if isinstance(tree, ast.Call) and isinstance(tree.func, ast.Name) and tree.func.id == "_guard" \
            and isinstance(tree.args[0], ast.JoinedStr):
        return tree.args[0]
    return _call("_text", tree)
