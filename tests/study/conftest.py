"""Small study specifications shared by the study tests."""

import pytest

SMALL = """
[study]
seeds = {seeds}
budget = {budget}
points = 10
na = 2
nb = 2
nk = 1
[grid]
predictors = ["simulation-rest", "one-step"]
parametrizations = ["coefficients", "reflection"]
[[data]]
name = "rig"
kind = "rig"
[[optimizer]]
label = "SDA"
method = "sda"
[[optimizer]]
label = "Eb-SDA"
method = "ebsda"
"""


@pytest.fixture
def small_spec(tmp_path):
    """Write a small study (2 seeds) and return its path."""

    def make(seeds=2, budget=300, name="spec.toml"):
        path = tmp_path / name
        path.write_text(SMALL.format(seeds=seeds, budget=budget))
        return path

    return make
