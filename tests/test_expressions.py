"""Template expressions: what users write works; what an attacker writes is refused
before it runs, or stopped by a limit, with a message that names the problem."""
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.templates.evaluator import evaluate as evaluate_compiled
from engine.templates.expressions import compile_expression, compile_statements
from engine.templates.functions import FUNCTIONS
from engine.templates.guards import MAX_INT_BITS, MAX_STRING_LENGTH


def evaluate(text, **scope):
    return evaluate_compiled(compile_expression(text), scope)


@pytest.mark.parametrize("text, scope, expected", [
    ('f"G25 X{Xmin:.2f}"', {"Xmin": 74.0}, "G25 X74.00"),
    ('"G25 X" + str(Xmin)', {"Xmin": 74}, "G25 X74"),
    ("round(sqrt(h * (da0 - h)), 3)", {"h": 4.5, "da0": 70}, 17.168),  # √294.75 = 17.1683,
    ('f"EGON(C,\\"FINE\\",B,{-z0},{z2})"', {"z0": 1, "z2": 19}, 'EGON(C,"FINE",B,-1,19)'),
    ("ctr_px == 'T' and shift != 0", {"ctr_px": "T", "shift": 2}, True),
    ("x if x > 0 else -x", {"x": -3}, 3),
    ("f'{x:>{w}}'", {"x": 7, "w": 4}, "   7"),
])
def test_python_expressions_evaluate_as_python_does(text, scope, expected):
    assert evaluate(text, **scope) == expected


@pytest.mark.parametrize("text, scope, expected", [
    ("ctr_px = 'T' AND shift <> 0", {"ctr_px": "T", "shift": 2}, True),
    ("ctr_px = 'T' AND shift <> 0", {"ctr_px": "T", "shift": 0}, False),
    ("ctr_px = 'T' AND shift <> 0", {"ctr_px": None, "shift": 2}, False),   # NULL is not true
    ("teeth / 2 = 9", {"teeth": 19}, True),                                 # SQL integer division
])
def test_sql_conditions_are_translated_with_sql_semantics(text, scope, expected):
    assert evaluate(text, **scope) is expected


def test_statements_are_assignments_in_order():
    statements = compile_statements("a = 1; b = a + 2\nc = f'{b}'")
    assert [name for name, _ in statements] == ["a", "b", "c"]


@pytest.mark.parametrize("text", [
    "open('/etc/passwd')",
    "__import__('os')",
    "().__class__.__bases__[0].__subclasses__()",
    "(lambda: 1)()",
    "[x for x in range(10)]",
    "x := 1",
    "eval('1')",
    "exec('1')",
    "getattr(x, 'y')",
    "f'{x!r}'",
    "globals()",
    "_secret",
])
def test_hostile_expressions_are_refused_before_running(text):
    with pytest.raises(EngineError):
        compile_expression(text)


@pytest.mark.parametrize("text", ["while True: pass", "import os", "for i in range(9): x = i",
                                  "def f(): pass", "x += 1", "a.b = 1", "print(1)"])
def test_only_assignments_are_statements(text):
    with pytest.raises(EngineError):
        compile_statements(text)


@pytest.mark.parametrize("text, limit", [
    ("9**9**9", f"{MAX_INT_BITS} bits"),
    ("'a'*10**9", f"{MAX_STRING_LENGTH} characters"),
    ("10**9*'a'", f"{MAX_STRING_LENGTH} characters"),
    ("1 << 10**6", f"{MAX_INT_BITS} bits"),
    ("f'{1:>999999999}'", "format width"),
    ("'%0999999999d' % 1", "f-string"),
    ("2**4000 * 2**4000", f"{MAX_INT_BITS} bits"),
])
def test_expressions_that_would_exhaust_memory_or_time_stop_at_a_limit(text, limit):
    with pytest.raises((ValueError, EngineError), match=limit):   # refused when compiled or when run
        evaluate(text)


def test_string_doubling_cannot_grow_without_bound():
    statements = compile_statements("s = s + s")
    scope = {"s": "x" * 1024}
    with pytest.raises(EngineError, match="characters"):
        for _ in range(64):
            scope["s"] = evaluate_compiled(statements[0][1], scope)
    assert len(scope["s"]) <= MAX_STRING_LENGTH


def test_oversized_expression_text_is_refused():
    with pytest.raises(EngineError, match="longer than"):
        compile_expression("1+" * 3000 + "1")


@pytest.mark.parametrize("text", [
    'f"G1 X{cut_x:.3f} F{feed:.1f}"', "round(cut_x * 2, 2)", "min(cut_x, feed) > 10",
    "'ROUGH' if feed > 30 else 'FINISH'", "360 * sin(radians(15)) / (pi * 2 * 30)",
])
def test_asteval_evaluation_agrees_with_python_on_ordinary_expressions(text):
    import math

    scope = {"cut_x": 51.5, "feed": 41.8}
    python = eval(text, {"__builtins__": {}, **FUNCTIONS, "pi": math.pi}, dict(scope))   # the reference
    assert evaluate(text, **scope) == python


# The gate reads the verdict on plain lines off their shape (engine.templates.plain_lines): it
# must be the full gate's verdict, tree for tree, name for name, refusal for refusal.
PLAIN_PIECES = st.one_of(
    st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters='"\\{}\n\r'), max_size=8),
    st.sampled_from(["{x}", "{x:.3f}", "{feed:+08.2f}", "{pi:.4f}", "{sin}", "{_x}", "{x!r}", "{x:9999}",
                     "{x:>{w}}", "{x + 1}", "{x:{'5'}}", "{{", "}}", "{True}", "{min(x, 1)}",
                     "{nc_number(x, '0.010')}", "{nc_number(feed, '-.4')}", "{nc_number(x, 1)}", "{nc_number(pi, '2')}",
                     "{nc_number(_x, '2')}", "{nc_number(x, '2'):>5}", "{nc_number(x)}", "{nc_number(sin, '1')}"]),
)


def full_verdict(text):
    import ast

    from engine.templates.expressions import _fully_checked

    try:
        compiled = _fully_checked(text, ast.parse(text.strip(), mode="eval"), False)
    except EngineError as error:
        return str(error)
    return ast.dump(compiled.tree, include_attributes=True), compiled.names, compiled.ordered_names, compiled.calls


def verdict(text):
    import ast

    try:
        compiled = compile_expression(text)
    except EngineError as error:
        return str(error)
    return ast.dump(compiled.tree, include_attributes=True), compiled.names, compiled.ordered_names, compiled.calls


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=300, deadline=None)
@given(st.lists(PLAIN_PIECES, max_size=12).map("".join), st.booleans())
def test_plain_lines_get_the_full_gate_s_verdict(body, f_string):
    text = ('f"' if f_string else '"') + body + '"'
    try:
        compile(text, "<line>", "eval")
    except SyntaxError:
        return   # not Python: the SQL route, which the shape reading never takes
    assert verdict(text) == full_verdict(text)


@pytest.mark.parametrize("text", ['"G0 Z5."', "12", "1.5", "2 ** 5000", "b'x'", 'f"{x:.1f}" + "y"', "True",
                                  'f"' + "{x}" * 150 + '"',   # more nodes than the gate allows
                                  'f"' + "{x}a" * 98 + "{x}{x}" + '"', 'f"' + "{x}a" * 99 + "{x}" + '"'])   # 400, 401
def test_written_constants_get_the_full_gate_s_verdict(text):
    assert verdict(text) == full_verdict(text)
