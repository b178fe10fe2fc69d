"""Argument types the benchmark scripts share (run as ``python
benchmarks/<script>.py``, which puts this folder on the import path)."""

import argparse


def seed_list(text: str) -> list[int]:
    """Seeds from ``"0-4"`` (inclusive) or ``"0,3,7"``, for argparse's
    ``type=``: a bad list is a usage error that names what was wrong.

    >>> seed_list("2-4"), seed_list("0,3")
    ([2, 3, 4], [0, 3])
    """
    try:
        if "-" in text:
            lo, hi = (int(part) for part in text.split("-"))
            seeds = list(range(lo, hi + 1))
        else:
            seeds = [int(part) for part in text.split(",")]
    except ValueError:
        seeds = []
    if not seeds or min(seeds) < 0:
        raise argparse.ArgumentTypeError(
            f"seeds must be a range like 0-4 or a list like 0,3 of "
            f"non-negative integers; got {text!r}"
        )
    return seeds
