"""A refusal after the search (issue 29, new-user review): the line names every choice tried but
each distinct reason once, and an input no choice can change (an unknown or unfitting --fixture, a
feed mode per unit on a gear of one unit, two cuts with a tangential feed) is refused at once with
its own words, not after the whole search. The seeded gears: 42 a spur gear (one unit), 53 a worm
wheel, 54 a cluster gear of two units."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from engine.errors import EngineError
from engine.gears.records import Hob
from engine.hobbing.choices import FEED_MODES, UNIT_FEED_MODES, Choices
from engine.programs.job_search import MAX_HOBS, attempts, first_that_fits

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guide" / "instantiate-and-batches.md"
HOBS = [Hob(f"H{n}", 2.0, 20.0, 1, 70.0, 100.0, "R", "A", "HSS", "TiN", "cylindrical") for n in range(1, 6)]
WORDS = {"fifteen": 15, "twenty-seven": 27}


def most_plannings(units: int) -> int:
    """The most jobs the search plans for a gear the model cuts once (m ≤ 3): one cut runs the
    roughing direction only (conventional-climb is conventional then), two cuts every mode; a
    cluster gear also each unit its own way; each with MAX_HOBS hobs."""
    per_unit = len(UNIT_FEED_MODES) if units == 2 else 0
    one_cut = len({rough for rough, _ in FEED_MODES.values()}) + per_unit
    return MAX_HOBS * (one_cut + len(FEED_MODES) + per_unit)


def test_the_guide_states_the_most_plannings_a_refused_gear_costs():
    text = " ".join(GUIDE.read_text(encoding="utf-8").split())
    stated = re.search(r"A refused gear costs up to (\S+) plannings .*?\((\S+) for a cluster gear", text)
    assert stated, "the guide says what a refusal costs"
    assert [WORDS[word] for word in stated.groups()] == [most_plannings(1), most_plannings(2)]
    assert len(attempts(HOBS, Choices(), 2.0, 1)) == most_plannings(1)
    assert len(attempts(HOBS, Choices(), 2.0, 2)) == most_plannings(2)


def test_distinct_reasons_are_said_once_and_tagged_on_the_choices():
    """Two kinds of refusal: the first choice's with its full words, the other once, each choice
    tried after it under the letter of its reason, in the order of the search."""
    def refuse(attempt):
        if attempt.cut_count(2.0) == 2:
            raise EngineError("gear 7: the rough cut leaves 0.4 mm; nothing stored")
        raise EngineError(f"gear 7: hob {attempt.hob.id} reaches unit 1; nothing stored")

    with pytest.raises(EngineError) as refused:
        first_that_fits(7, 2.0, attempts(HOBS[:2], Choices(), 2.0), refuse)
    message = str(refused.value)
    assert message == (
        "gear 7: no choice fits: the first choice [climb, hob H1, 1 cut] hob H1 reaches unit 1; also tried, "
        "in order: (a) [conventional, hob H1, 1 cut], [climb, hob H2, 1 cut], [conventional, hob H2, 1 cut], "
        "(b) [climb, hob H1, 2 cuts], [conventional, hob H1, 2 cuts], [conventional-climb, hob H1, 2 cuts], "
        "[climb, hob H2, 2 cuts], [conventional, hob H2, 2 cuts], [conventional-climb, hob H2, 2 cuts]; "
        "(a) is the first choice's reason, numbers aside, and (b) is: the rough cut leaves 0.4 mm; nothing stored")


@pytest.mark.parametrize(("args", "words"), [
    (("--gear", "42", "--fixture", "NOPE"), "work-holding 'NOPE' does not exist"),
    (("--gear", "42", "--feed-mode", "climb/conventional"), "names one for each of 2 units; the gear has 1"),
    (("--gear", "53", "--cuts", "2", "--worm-feed", "tangential"), "two cuts with a tangential feed"),
])
def test_an_input_no_choice_changes_is_refused_at_once(read_only_run, args, words):
    refused = read_only_run("instantiate", *args)
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1, refused.output
    assert words in refused.stderr
    assert "tried" not in refused.stderr and "[" not in refused.stderr, "no search around it"
