
-- How an imported NC file ended its lines (issue 17): LF or CRLF, and whether its last line
-- ended with one. The rows hold the lines without them, so `M17` of a CRLF file and of an LF
-- file is one component; writing the class's program back uses these to give the file byte for byte.
ALTER TABLE gear_class ADD COLUMN line_ending text NOT NULL DEFAULT E'\n'
    CHECK (line_ending IN (E'\n', E'\r\n'));
ALTER TABLE gear_class ADD COLUMN final_newline boolean NOT NULL DEFAULT true;
