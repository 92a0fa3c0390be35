"""One repair over many files: planning, isolated workers with time limits, resume, and
the summary (``meshvis batch``)."""
