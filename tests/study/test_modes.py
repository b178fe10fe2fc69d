"""A study's rig record with ``all_outputs = true``: the rig's modes from
every sensor of the same run, once per record, stored, resumed and
reported."""

import json
import sqlite3

import numpy as np
import pytest

import spiralid.study.modes as modes_module
from spiralid.fms import FlexibleManipulator
from spiralid.report.study_output import (
    _html,
    partial_note,
    study_results_dict,
    study_summary,
)
from spiralid.study import (
    ResultStore,
    analyse,
    load_records,
    parse_spec,
    run_study,
)

TINY = """
[study]
seeds = [3]
budget = 100
points = 10
na = 2
nb = 2
nk = 1
baselines = ["ls"]
[grid]
predictors = ["simulation-rest"]
parametrizations = ["coefficients"]
[[data]]
name = "rig"
kind = "rig"
{extra}
[[optimizer]]
label = "SDA"
method = "sda"
"""


def _spec(extra: str = "all_outputs = true"):
    return parse_spec(TINY.format(extra=extra))


@pytest.fixture(scope="module")
def studied(tmp_path_factory):
    """A one-run study with the modes from every sensor, its store and
    what running it did."""
    store = tmp_path_factory.mktemp("modes") / "study.sqlite"
    spec = _spec()
    return spec, store, run_study(spec, store, engine="local")


@pytest.fixture(scope="module")
def results(studied):
    spec, store, _ = studied
    with ResultStore.open(store, readonly=True) as db:
        return analyse(db.rows(), spec, modes=db.modes())


# -- the specification ----------------------------------------------------------


@pytest.mark.parametrize(
    "record",
    [
        'name = "arm"\nkind = "arm"',
        'name = "mine"\nkind = "csv"\npath = "x.csv"',
    ],
)
def test_the_option_is_refused_for_records_of_one_sensor(record):
    text = TINY.format(extra="").replace('name = "rig"\nkind = "rig"', record)
    with pytest.raises(ValueError) as err:
        parse_spec(text.replace("[[optimizer]]", "all_outputs = true\n[[optimizer]]"))
    message = str(err.value)
    assert "`all_outputs` applies to kind 'rig' only" in message
    assert "\n" not in message


@pytest.mark.parametrize("value", ['"yes"', "1", "[true]"])
def test_the_option_must_be_a_bool(value):
    with pytest.raises(ValueError) as err:
        _spec(f"all_outputs = {value}")
    assert "`all_outputs` must be true or false" in str(err.value)
    assert "\n" not in str(err.value)


def test_the_digest_changes_only_when_the_option_is_set():
    plain, off, on = _spec(""), _spec("all_outputs = false"), _spec()
    assert plain.digest() == off.digest() != on.digest()
    assert not plain.data[0].all_outputs and not off.data[0].all_outputs
    assert on.data[0].all_outputs
    # The runs are the same: only the modes are added.
    assert plain.n_runs == on.n_runs == 2


# -- running, resuming ---------------------------------------------------------


def test_the_modes_are_the_fem_s(studied, results):
    _, _, run = studied
    assert (run.modes_computed, run.modes_reused, run.computed) == (1, 0, 2)
    fit = results.modes["rig"]
    fem = FlexibleManipulator().modes(3)
    found = fit.model.modes.table.frequency
    for f in fem:
        assert np.min(np.abs(found - f)) / f < 0.005, (f, found)
    np.testing.assert_allclose(fit.fem_hz, fem)
    # Seeded by the study's first seed, as the reproduction seeds its fit.
    assert fit.seed == 3 and fit.model.integrators == (2, 1, 0, 0)
    # Read back from the store with the intervals (the covariance is kept).
    assert np.all(np.isfinite(fit.model.modes.table.frequency_interval))
    assert 90 < fit.fits["validation"]["joint"] <= 100


def test_a_rerun_reuses_the_stored_modes(studied, monkeypatch):
    spec, store, _ = studied
    calls = []
    monkeypatch.setattr(
        modes_module, "fit_every_sensor", lambda *a, **k: calls.append(a)
    )
    with sqlite3.connect(store) as db:
        before = db.execute("SELECT result FROM modes").fetchall()
    again = run_study(spec, store, engine="local")
    assert calls == []
    assert (again.modes_reused, again.modes_computed, again.computed) == (1, 0, 0)
    with sqlite3.connect(store) as db:
        assert db.execute("SELECT result FROM modes").fetchall() == before


def test_the_fit_uses_the_record_s_own_run(tmp_path, monkeypatch):
    # Another rig and noise seed: the sensors handed to the fit are those of
    # the run the study's single-output record comes from.
    spec = _spec("noise_seed = 4\nrig = { payload_mass = 0.05 }\nall_outputs = true")
    seen = []

    def fake(record, fraction, seed, rig=None):
        seen.append((record, fraction, seed, rig))
        raise RuntimeError("stop here")

    monkeypatch.setattr(modes_module, "fit_every_sensor", fake)
    with pytest.raises(RuntimeError, match="stop here"):
        run_study(spec, tmp_path / "s.sqlite", engine="local")
    (record, fraction, seed, rig), *_ = seen
    single = load_records(spec)["rig"]
    np.testing.assert_array_equal(record.output("end_acceleration").y, single.y)
    np.testing.assert_array_equal(record.u, single.u)
    assert record.output_names == modes_module.RIG_OUTPUTS
    assert rig == FlexibleManipulator(payload_mass=0.05)
    assert (fraction, seed) == (spec.fraction, 3)


def test_a_store_without_modes_reads_as_before(tmp_path):
    spec = _spec("")
    store = tmp_path / "s.sqlite"
    run = run_study(spec, store, engine="local")
    assert (run.modes_computed, run.modes_reused) == (0, 0)
    with sqlite3.connect(store) as db:
        tables = {n for (n,) in db.execute("SELECT name FROM sqlite_master")}
    # No table added: the store is the one older versions wrote and read.
    assert "modes" not in tables
    with ResultStore.open(store, readonly=True) as db:
        assert db.modes() == {}
        res = analyse(db.rows(), spec, modes=db.modes())
    assert res.modes == {}
    assert "modes_from_every_sensor" not in study_results_dict(res, "")
    assert "Modes from every sensor" not in _html(res, {}, "", None)
    assert "Modes from every sensor" not in study_summary(res)


def test_a_store_stopped_before_the_fit_says_what_is_missing(studied, results):
    """A store interrupted after its runs but before its fit from every
    sensor: the report said nothing of the section it left out."""
    spec, store, _ = studied
    assert results.missing_modes == () and partial_note(results) == ""
    with ResultStore.open(store, readonly=True) as db:
        res = analyse(db.rows(), spec, modes={})
    assert res.missing_runs == 0 and res.missing_modes == ("rig",)
    note = partial_note(res)
    assert "no modes from every sensor of 'rig'" in note
    assert study_summary(res).startswith(f"Partial study: {note}.")


# -- the report ----------------------------------------------------------------


def test_the_report_holds_the_section(results):
    page = _html(results, {}, TINY, None)
    head = "<h2>Modes from every sensor: rig</h2>"
    assert head in page
    section = page.split(head)[1].split("<h2>")[0]
    assert "share in tip_deflection (%)" in section
    assert "FEM (rig.modes(3))" in section and "fit % (validation)" in section
    # The shared fit and every single-output model beside the FEM.
    comparison = results.modes_comparison("rig")
    assert [r["model"] for r in comparison] == [
        "every sensor",
        "SDA (simulation-rest, coefficients)",
        "LS (simulation-rest)",
    ]
    assert max(abs(e) for e in comparison[0]["error_percent"]) < 0.5
    for row in comparison:
        assert f"<td>{row['model']}</td>" in section
    d = json.loads(json.dumps(study_results_dict(results, TINY)))
    every = d["modes_from_every_sensor"]["rig"]
    assert every["integrators"] == [2, 1, 0, 0]
    assert every["comparison"][0]["model"] == "every sensor"
    assert "Modes from every sensor: rig" in study_summary(results)
