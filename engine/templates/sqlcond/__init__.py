"""Translate a SQL condition (PostgreSQL flavour) into a Python ``ast.expr``.

Template rows hold conditions that users may type either as Python or "the way a
DBA writes SQL", e.g. ``ctr_px = 'T' AND shift <> 0``.  The expression compiler
tries Python first; when the text is not a Python expression it calls
:func:`translate`, validates the returned node and compiles it.  The compiled
code is evaluated with :data:`SQL_RUNTIME` and the template parameters as names.

Public surface
--------------
``SQL_RUNTIME``
    dict of the helper functions the translated tree calls; every name starts
    with ``_sql_``.  ``_sql_truth(x)`` turns a three-valued result into a bool
    (True only for True); the translated tree itself never coerces.
``translate(text) -> ast.expr``
    raises :class:`engine.errors.EngineError` with a one-line message.

The returned tree consists only of ``ast.Call`` (``func`` is an ``ast.Name`` of
a ``_sql_*`` helper, positional arguments only), ``ast.Name`` (parameter
references, Load context, spelled exactly as typed) and ``ast.Constant``
(int, float, str, bool, None).  Every ``ast.Name`` that is not in a ``func``
position is a parameter reference.

Supported SQL
-------------
* literals: ``'text'`` (``''`` escapes), integers, decimals (as float),
  ``TRUE``, ``FALSE``, ``NULL``; identifiers, unquoted or ``"double quoted"``,
  that are Python identifiers (not keywords, not starting with ``_sql_``).
* comparisons ``= <> != < <= > >=``, ``IS [NOT] NULL``, ``ISNULL``,
  ``NOTNULL``, ``IS [NOT] TRUE``, ``IS [NOT] FALSE``, ``IS [NOT] UNKNOWN``,
  ``IS [NOT] DISTINCT FROM``, ``[NOT] BETWEEN [SYMMETRIC] a AND b``,
  ``[NOT] IN (list)``, ``[NOT] LIKE`` / ``[NOT] ILIKE`` (``%``, ``_``,
  backslash escape or ``ESCAPE 'c'``).
* ``AND``, ``OR``, ``NOT`` with SQL three-valued logic.
* ``+ - * / %``, unary ``-``, ``^`` (power), ``||`` (text concatenation).
* ``CASE [x] WHEN ... THEN ... [ELSE ...] END``, ``COALESCE``, ``NULLIF``,
  ``ABS``, ``CEIL``/``CEILING``, ``FLOOR``, ``ROUND(x[, n])``, ``SQRT``,
  ``POWER``/``POW``, ``MOD``, ``LEAST``, ``GREATEST``.

Semantics
---------
* NULL is Python None.  Comparisons, arithmetic, ``||``, LIKE and IN follow
  SQL NULL rules; AND/OR/NOT use the three-valued truth table.
* AND, OR, CASE and COALESCE evaluate their operands left to right and stop as
  soon as the result is known (as PostgreSQL does in practice), so
  ``b <> 0 AND a / b > 1`` and ``CASE WHEN b = 0 THEN 0 ELSE a / b END`` do
  not divide by zero.  Operands after the first that might raise are passed to
  the helper as thunks built by ``_sql_defer``.
* No implicit casts: text never equals a number and a boolean never equals a
  number (the result is FALSE); ordering comparisons between them raise
  TypeError.  AND/OR/NOT and CASE WHEN conditions need boolean operands,
  arithmetic needs numbers (booleans are not numbers), otherwise TypeError.
* ``/`` on two integers truncates toward zero (``-7 / 2`` is ``-3``); with a
  float or Decimal operand it is ordinary division.  ``%`` takes the sign of
  the dividend.  Division or modulo by zero raises
  ``ZeroDivisionError("division by zero")``.
* ``^``/``POWER`` return float; ``ROUND`` rounds half away from zero (like
  PostgreSQL's numeric), returning the argument's type.
* ``x || y`` needs at least one text operand; the other is rendered as text
  (booleans as ``true``/``false``).
* Results are bounded like the rest of the expression engine: ``+ - *`` raise
  OverflowError beyond MAX_INT_BITS, ``||`` raises ValueError beyond
  MAX_TEXT_LENGTH characters.

Not supported (rejected with EngineError): subqueries, ``*``, qualified names
(``t.x``), casts, arrays, JSON operators, parameters/placeholders, any other
function, more than one statement.

Modules
-------
``translate`` (sqlglot tree -> ``ast.expr``, handlers by node type) and ``parse``
(SQL text -> sqlglot tree) run once per template; ``runtime`` assembles
``SQL_RUNTIME`` from ``logic``, ``compare``, ``text`` and ``arithmetic``, which
share the operand checks in ``operands``.
"""

from __future__ import annotations

from . import operands

# `translate` (engine.templates.sqlcond.translate) imports sqlglot, a tenth of a second: it is
# imported only where a condition is translated, not where translated conditions run (runtime).

# The limits named above, importable from here as before the package split.
MAX_INT_BITS = operands.MAX_INT_BITS
MAX_TEXT_LENGTH = operands.MAX_TEXT_LENGTH
