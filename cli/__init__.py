"""The ``meshvis`` command line: parse, call the library, report.  No algorithms here."""
