"""Benchmarks behind ``meshvis bench``: reproducible measurements, one module per benchmark.

Each module has a ``run(...)`` returning a dict and a ``format(result)`` returning text.
Times are compared as ratios measured in one run.
"""
