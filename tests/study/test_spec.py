"""Study specifications: the shipped default, and one-line errors for bad ones."""

import pytest

from spiralid.study import (
    DEFAULT_SPEC,
    load_records,
    load_spec,
    parse_spec,
    study_tasks,
)
from spiralid.study.spec import PREDICTORS


def test_default_spec_is_the_papers_grid():
    spec = load_spec()
    assert spec.seeds == tuple(range(20))
    assert spec.budget == 20_000 and (spec.na, spec.nb, spec.nk) == (8, 8, 0)
    assert spec.predictors == tuple(PREDICTORS)
    assert set(spec.parametrizations) == {"coefficients", "reflection"}
    assert {o.method for o in spec.optimizers} >= {"sda", "ebsda"}
    assert [d.kind for d in spec.data] == ["rig", "arm"]
    assert spec.fraction == pytest.approx(2 / 3)
    assert spec.source == DEFAULT_SPEC.read_text()


def test_tasks_cross_every_reading_and_seed(small_spec):
    spec = load_spec(small_spec(seeds=3))
    tasks = study_tasks(spec, load_records(spec))
    searches = [t for t in tasks if t.seed is not None]
    # 1 record x 2 predictors x 2 parametrisations x 2 optimisers x 3 seeds,
    # plus LS and OE per record and predictor.
    assert len(searches) == 24 and len(tasks) == 24 + 4
    assert len({t.key for t in tasks}) == len(tasks)
    # A key depends on what decides the result, and on nothing else.
    again = study_tasks(spec, load_records(spec))
    assert [t.key for t in again] == [t.key for t in tasks]


BASE = """
[study]
seeds = 2
[[data]]
kind = "rig"
[[optimizer]]
method = "sda"
"""


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (BASE + "[grid]\ncolour = 1\n", "unknown key 'colour' in \\[grid\\]"),
        (BASE + "[extra]\n", "unknown key 'extra' in the top level"),
        (BASE.replace('"sda"', '"simplex"'), "unknown method 'simplex'"),
        (BASE.replace("seeds = 2", "seeds = 0"), "`seeds` must be an integer >= 1"),
        (BASE.replace("seeds = 2", "seeds = []"), "`seeds` must be >= 1"),
        (BASE + "[grid]\npredictors = []\n", "`predictors` must be a non-empty list"),
        ('[study]\nseeds = 2\n[[optimizer]]\nmethod = "sda"\n', "the grid is empty"),
        (BASE.replace('[[optimizer]]\nmethod = "sda"\n', ""), "the grid is empty"),
        (BASE + '[grid]\npredictors = ["two-step"]\n', "unknown predictor 'two-step'"),
        (BASE.replace('kind = "rig"', 'kind = "wav"'), "`kind` must be one of"),
        (BASE.replace("seeds = 2", 'fraction = "3/2"'), "`fraction` must be"),
        ("[study\n", "not valid TOML"),
    ],
)
def test_bad_specification_is_one_clear_line(text, message):
    with pytest.raises(ValueError, match=message) as info:
        parse_spec(text)
    assert "\n" not in str(info.value)


def test_unreadable_record_fails_before_any_run(tmp_path):
    spec = parse_spec(
        BASE.replace('kind = "rig"', 'name = "mine"\nkind = "csv"\npath = "no.csv"'),
        base=tmp_path,
    )
    with pytest.raises(ValueError, match="record 'mine' \\(csv\\)"):
        load_records(spec)


def test_orders_too_large_for_a_record_fail_before_any_run(tmp_path):
    (tmp_path / "tiny.csv").write_text("u,y\n" + "1,2\n0,1\n" * 6)
    spec = parse_spec(
        BASE.replace(
            'kind = "rig"', 'name = "t"\nkind = "csv"\npath = "tiny.csv"\nts = 1'
        ),
        base=tmp_path,
    )
    with pytest.raises(ValueError, match="record 't'"):
        load_records(spec)


def test_missing_specification_file(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        load_spec(tmp_path / "nope.toml")
