"""NC text primitives (design notes §5, §7): tokens of one NC line, the layout of a program's text
(its opening, ending and line breaks) and the lineage line a program carries. Plain text rules
that every section above reads; they import nothing of the engine but its top-level modules."""
