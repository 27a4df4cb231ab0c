-- Issue 16, after review: what reads as a lineage line at the control (migration 0021). The
-- comment may follow a block number or a move (`N10 ; PROGRAM 1 TEMPLATE …`), and only a program
-- id or DRY-RUN makes one (`; program from template of spur` is a shop's comment, not a lineage).
-- The spaces are spelled out rather than \s, whose meaning depends on the server's locale, so the
-- database reads exactly the lines engine.programs.lineage.LINEAGE_SHAPE reads.
CREATE OR REPLACE FUNCTION lineage_shaped(line text) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN line ~* ('[;(][ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]*'
                'PROGRAM[ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]+'
                '([0-9]+|DRY-RUN)[ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]+'
                'TEMPLATE');
