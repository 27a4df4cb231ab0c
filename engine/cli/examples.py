"""One example invocation per command, shown as the last line of its --help (`Example: ...`).

A command whose docstring has its own `Example:` line needs no entry here (engine.cli.conventions
moves that line to the end of the help). Every command of `engine` has one or the other
(tests/test_cli_conventions.py walks them all).
"""
from __future__ import annotations

EXAMPLES = {
    "engine": "engine instantiate --gear 42",
    "engine demo": "engine demo --gear 42",
    "engine db": "engine db status",
    "engine db migrate": "DATABASE_URL=postgresql://engine@dbhost/gears engine db migrate",
    "engine db status": "engine db status",
    "engine jobs": "engine jobs list --gear 42",
    "engine seed": "engine seed",
    "engine gears": "engine gears import gears.csv",
    "engine gears import": "engine gears import gears.csv --json",
    "engine gears units": "engine gears units units.csv",
    "engine classify": "engine classify --gear 42",
    "engine instantiate": "engine instantiate --gear 42 --out /srv/nc/hobber/",
    "engine template": "engine template export --class spur --out spur.csv",
    "engine template shared": "engine template shared --class helical",
    "engine template list": "engine template list",
    "engine template export": "engine template export --class spur --out spur.csv",
    "engine template import": "engine template import --class spur spur.csv",
    "engine template diff": "engine template diff --class spur --from 3 --to 4",
    "engine template restore": "engine template restore --class spur --version 3",
    "engine lint": "engine lint --json",
    "engine hobs": "engine hobs match --gear 42",
    "engine hobs list": "engine hobs list --json",
    "engine hobs add": ("engine hobs add --id H-M2-AA-R1 --module 2 --tip-diameter 80 --length 100 "
                        "--hand R --accuracy-class AA"),
    "engine hobs import": "engine hobs import hobs.csv",
    "engine hobs match": "engine hobs match --gear 42 --shift-travel 20",
    "engine suggest": "engine suggest --gear 42 --top 5",
    "engine cases": "engine cases list",
    "engine cases list": "engine cases list --json",
    "engine cases confirm": "engine cases confirm --job 17",
    "engine import-nc": "engine import-nc proven.MPF --class spur_special --parent spur --params params.json",
    "engine refactor": "engine refactor --threshold 0.85 --json >> refactor.jsonl",
    "engine import-dxf": "engine import-dxf shaft.dxf --machine lathe-840d --json",
    "engine plot": "engine plot --job 17 --out job17.svg",
    "engine programs": "engine programs show 812",
    "engine config": "engine config show",
    "engine config path": "engine config path",
    "engine config show": "engine config show",
}
