"""IEC 61131-7 Fuzzy Control Language: parser, checks, writer and conformance report."""
