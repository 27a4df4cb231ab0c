"""`engine seed --samples` on a database holding a shop's own gears under sample ids (issue 16):
the samples' golden tests and further units are attached only to gears that are the samples, and
the report says how many tests were left out, and why."""
from __future__ import annotations

import json

import psycopg
import pytest
from click.testing import CliRunner

from engine.cli.app import main
from engine.paths import SEED_DIR

SHOP_GEARS = ("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material) VALUES "
              "(42, 'spur', 3, 33, 0, 20, 'C45'), (54, 'spur', 2.5, 41, 0, 18, 'C45')")


def engine_on(url: str, *args):
    result = CliRunner().invoke(main, ["--database-url", url, *args], env={"ENGINE_CONFIG": ""})
    assert result.exit_code == 0, result.output
    return result


def invoke_with(url: str, env: dict, *args):
    """The CLI in-process with the environment variables given (and no config file)."""
    return CliRunner().invoke(main, ["--database-url", url, *map(str, args)], env={"ENGINE_CONFIG": "", **env})


def sample_tests_of(gear_id: int) -> int:
    tests = json.loads((SEED_DIR / "template_tests.json").read_text(encoding="utf-8"))
    return sum(test.get("gear_id") == gear_id for test in tests)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_samples_leave_a_shops_own_gears_without_their_tests_and_units(empty_database_url):
    url = empty_database_url
    engine_on(url, "db", "migrate")
    engine_on(url, "seed")
    with psycopg.connect(url) as conn:
        conn.execute(SHOP_GEARS)
    seeded = engine_on(url, "seed", "--samples").stdout
    assert f"skipped {sample_tests_of(42)} golden tests of sample gear 42: gear 42 here is not the sample" in seeded
    assert "of sample gear 54: gear 54 here is not the sample" in seeded
    with psycopg.connect(url) as conn:
        attached = conn.execute("SELECT count(*) FROM template_test WHERE gear_id IN (42, 54)").fetchone()[0]
        units = conn.execute("SELECT count(*) FROM gear_unit WHERE gear_id = 54").fetchone()[0]
        of_samples = conn.execute("SELECT count(*) FROM template_test WHERE gear_id = 43").fetchone()[0]
    assert (attached, units) == (0, 0)
    assert of_samples == sample_tests_of(43) > 0   # the gears the seed added get theirs


def test_a_second_seed_of_the_samples_changes_nothing_and_says_nothing_skipped(fresh_database_url):
    seeded = engine_on(fresh_database_url, "seed", "--samples").stdout
    assert seeded == "seed: everything was already there; nothing changed\n"


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_samples_do_not_hang_golden_tests_on_a_shops_own_gear(empty_database_url):
    """A shop's own gear 42 (m3 z33), then `engine seed --samples`: the sample golden tests of
    gear 42 (m2 z19) must not be attached to the shop's gear (which then can never be deleted)."""
    for args in (("db", "migrate"), ("seed",)):
        assert invoke_with(empty_database_url, {}, *args).exit_code == 0
    with psycopg.connect(empty_database_url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material) "
                     "VALUES (42, 'spur', 3, 33, 0, 20, 'C45')")
    seeded = invoke_with(empty_database_url, {}, "seed", "--samples")
    with psycopg.connect(empty_database_url) as conn:
        attached = conn.execute("SELECT count(*) FROM template_test WHERE gear_id = 42").fetchone()[0]
    assert seeded.exit_code == 1 or attached == 0, seeded.output
