"""The argument types the benchmark scripts share (benchmarks/_cli.py)."""

import argparse
import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "_cli.py"
spec = importlib.util.spec_from_file_location("_cli", SCRIPT)
_cli = importlib.util.module_from_spec(spec)
spec.loader.exec_module(_cli)


@pytest.mark.parametrize(
    ("text", "seeds"),
    [("0-4", [0, 1, 2, 3, 4]), ("7", [7]), ("0,3,9", [0, 3, 9]), ("5-5", [5])],
)
def test_seed_list_reads_ranges_and_lists(text, seeds):
    assert _cli.seed_list(text) == seeds


@pytest.mark.parametrize("text", ["", "a-b", "4-1", "1,x", "-3", "1-2-3"])
def test_seed_list_refuses_what_is_no_seed_list(text):
    with pytest.raises(argparse.ArgumentTypeError, match="seeds must be"):
        _cli.seed_list(text)


def test_a_bad_seed_list_is_a_usage_error():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=_cli.seed_list)
    with pytest.raises(SystemExit):
        parser.parse_args(["--seeds", "zero"])
    assert parser.parse_args(["--seeds", "2-3"]).seeds == [2, 3]
