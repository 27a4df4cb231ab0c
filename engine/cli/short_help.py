"""Each command's short help, as `engine --help` lists it, without importing the command (issue
12's start-up: the listing imported all 26 command modules, 1.16x the start-up of 30ac394).
The text is the command's own (its docstring's first sentence, click's get_short_help_str without a
length limit); tests/test_startup.py checks each entry against the command it names, so a changed
docstring fails there with the line to write here. The listing has click shorten it to the
terminal's width (engine.cli.app.EngineGroup.format_commands)."""
from __future__ import annotations

SHORT_HELP = {
    "demo": (
        "Migrate, seed (with the samples) and instantiate one gear in the database engine_demo of the "
        "embedded PostgreSQL; print the program."),
    "db": (
        "The database: apply or list the numbered SQL migrations; the URL in use, psql on it, stopping "
        "the embedded PostgreSQL; backing it up to a file and restoring it."),
    "seed": (
        "Load seed_templates/ (adds only what is missing, overwrites nothing): the class tree, the "
        "standard code of every class (released), the machine records and the golden tests that need no "
        "sample gear."),
    "gears": "Workpieces: import them from CSV (columns of design notes §9).",
    "classify": (
        "Explain a gear's class: the group-technology decision path (face-width variation, generating "
        "line, units), the class stored, its hobbing model and the hob it gets."),
    "instantiate": (
        "Produce the NC program of a gear (or a stored job, a job of an imported class, or a batch of "
        "gears)."),
    "explain": "Say for every template row of a program whether it ran and emitted, and why.",
    "template": (
        "Templates of gear classes: list, export and import as CSV (id,t,n,p_calc,s,o,p_emit, and "
        "line_ending,final_newline for a class not LF with a final newline); history, diff and restore of"
        " their versions."),
    "lint": "Check every expression of every template: parses, is allowed, names known parameters.",
    "hobs": "Hob library: list, show, add, import from CSV, delete, and match a hob to a gear.",
    "machines": "Machine records: which machines exist, the dialect each runs and its limits.",
    "suggest": "Propose hob speed and feeds for a gear from the nearest cases of the machining history.",
    "cases": "The machining history (cutting cases) that `engine suggest` reasons over.",
    "import-nc": "Import NC_FILE as the class's template: one row per line, all or nothing.",
    "refactor": "Merge identical component bodies and report near-duplicate lines to unify.",
    "import-dxf": (
        "Make DXF_FILE a turning job: profile on layer 0 (or --profile-layer), operation n on layer n "
        "with its @-codes."),
    "plot": (
        "Draw a job (turning: profile, blank, every pass, X as diameter; hobbing: side view of blank, hob"
        " and passes, the numbers read from the program — swivel A with its sign, centre distance and "
        "depth per cut, feeds, shift range — and the gear's teeth beside the hob's thread; a worm wheel "
        "also from above) or a stored program, as PNG or SVG."),
    "simulate": (
        "Simulate a stored hobbing or turning program: collisions of the hob (tip cylinder, length, "
        "swivel) with the blank, its units, the fixture and the tailstock; the teeth, hand and lead the "
        "coupling generates and the swivel, against the gear; depth, stock and run-out per cut; the table"
        " speed; the feed per workpiece revolution; the cycle time against the header."),
    "programs": "Stored programs: list them, show one by id, or find it from the hash on its lineage line.",
    "test": (
        "Run the golden tests of the templates: each makes its program in memory (nothing stored) and "
        "checks its expectations."),
    "jobs": "Jobs: a gear on a machine with every parameter its template needs; list, show, delete.",
    "config": (
        "The config file: option defaults, the default machine, output folder and line endings per "
        "machine (docs/guide/configuration.md)."),
    "fixtures": (
        "Work-holding library: arbors, mandrels, collets and centres a gear is clamped on (list, import, "
        "match)."),
    "materials": (
        "Workpiece materials: group, hardness and the cutting speeds of reference §C by hob material and "
        "coating (list, show, import)."),
    "serve": (
        "Serve the web view of gears, jobs and programs (each page also as JSON with `Accept: "
        "application/json`) on the database in use, until Ctrl-C (exit 130) or `engine serve stop`."),
    "plant": (
        "Plants and their head office, by PostgreSQL's logical replication: the head office publishes its"
        " released templates and the records they run on; each plant receives them read-only, makes and "
        "proves its programs itself, and publishes its history (jobs, programs, requests) back."),
}
