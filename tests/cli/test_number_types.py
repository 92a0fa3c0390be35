"""The command line's number types, shared by the commands that take them."""

from __future__ import annotations

import argparse

import pytest

from meshvis.cli.common import non_negative_float, positive_seconds


def test_non_negative_float():
    assert non_negative_float("0") == 0.0 and non_negative_float("2.5") == 2.5
    for text in ("-1", "nan"):
        with pytest.raises(argparse.ArgumentTypeError, match="at least 0"):
            non_negative_float(text)


def test_positive_seconds():
    assert positive_seconds("0.5") == 0.5
    for text in ("0", "-3", "inf", "nan", "abc"):
        with pytest.raises(argparse.ArgumentTypeError, match="seconds"):
            positive_seconds(text)
