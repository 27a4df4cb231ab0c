"""Notes with a kind (issue 31): what the operator should know of a program, one line each, and
which kind of thing it says, so a batch of 3,000 gears can count its notes by kind ("feed
bounded": 1,003) instead of printing every one. The kind is given where the note is made, never
read back from its words; a note is still its text everywhere a note was a string (printed,
joined, stored as JSON). A plain string note has the kind OTHER."""
from __future__ import annotations

OTHER = "other"

# kind -> what a note of it says (docs/cli.md: engine instantiate's batch summary)
NOTE_KINDS = {
    "feed bounded": "an axial feed lowered to the table's or the feed marks' maximum",
    "hob speed bounded": "the hob speed lowered to the upper end of the cutting-speed table",
    "no hunting tooth": "the hob's starts and the gear's teeth share a factor",
    "no floor-to-floor time": "the machine states some of its floor-to-floor times but not all",
    OTHER: "any other note",
}


class Note(str):
    """A note's text, and its kind (a key of NOTE_KINDS)."""

    kind: str

    def __new__(cls, text: str, kind: str) -> Note:
        assert kind in NOTE_KINDS, kind   # a kind is one of the table's, named where the note is made
        note = super().__new__(cls, text)
        note.kind = kind
        return note

    def __reduce__(self):   # batch workers send notes back pickled
        return Note, (str(self), self.kind)


def kind_of(note: str) -> str:
    """The note's kind; OTHER for a plain string."""
    return getattr(note, "kind", OTHER)


def prefixed(prefix: str, note: str) -> str:
    """The note said of something (`GEAR42: …`, `gear 42: …`), its kind kept."""
    return Note(prefix + note, kind_of(note))


def replaced_head(note: str, old: str, new: str) -> str:
    """The note with its leading `old` said as `new` (`rough:` → `single cut:`), its kind kept."""
    return Note(new + note.removeprefix(old), kind_of(note)) if note.startswith(old) else note
