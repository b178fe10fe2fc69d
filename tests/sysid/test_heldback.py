"""The recommended method's choice among its distinct minima on the
held-back end of the estimation record (issue 27, item 3;
`spiralid.sysid.estimation.spiral.heldback`)."""

import numpy as np
import pytest
from scipy import signal

from spiralid.sysid import ARX, IdentifiedModel, IOData, identify, validate
from spiralid.sysid.estimation.core.cost import PaperCost
from spiralid.sysid.estimation.spiral import heldback


def _record(seed=0, n=600, drift=0.0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = signal.lfilter([0.0, 0.5, 0.3], [1.0, -1.5, 0.8], u)
    y += 0.02 * rng.standard_normal(n) + drift * np.cumsum(rng.standard_normal(n))
    return IOData(u, y, ts=0.01)


def test_the_held_back_error_is_the_free_run_from_rest_scored_on_the_end():
    data = _record()
    theta = np.array([-1.4, 0.7, 0.4, 0.3])
    cost = PaperCost(ARX(2, 2, 1), data)
    # By hand: the model run over the whole record from rest, then the RMS
    # of the last 150 samples' error.
    y_sim = signal.lfilter([0.0, 0.4, 0.3], [1.0, -1.4, 0.7], data.u)
    by_hand = np.sqrt(np.mean((data.y[450:] - y_sim[450:]) ** 2))
    assert heldback.held_back_rms(theta, cost, 450) == pytest.approx(by_hand, rel=1e-12)


def _c(name, held, cost):
    return heldback.Candidate(name, np.zeros(2), held, np.zeros(2), cost)


def test_the_lowest_cost_stays_unless_another_minimum_is_clearly_better_held_back():
    lowest, other = _c("search", 1.0, 2.0), _c("ls", 0.97, 2.5)
    # 3 % lower held-back error is within MARGIN (5 %): the lowest cost stays.
    assert heldback.select([lowest, other]) == ("search", "search")
    clearly = _c("ls", 0.9, 2.5)
    assert heldback.select([lowest, clearly]) == ("ls", "search")
    sel = heldback.Selection(0.2, 100, [lowest, clearly], "ls", "search")
    assert sel.overrode_cost
    assert "over the lowest cost, the search's best" in sel.sentence()
    assert sel.to_dict()["note"] == sel.sentence()


def test_a_refit_cut_short_may_not_override_the_lowest_cost_when_told():
    lowest, clearly = _c("search", 1.0, 2.0), _c("ls", 0.9, 2.5)
    clearly.capped = True
    # Trusted (the default, as stop="converged" chooses): the held-back
    # error decides; untrusted (stop="work"): the capped score cannot.
    assert heldback.select([lowest, clearly]) == ("ls", "search")
    assert heldback.select([lowest, clearly], trust_capped=False) == (
        "search",
        "search",
    )
    # The lowest cost's own refit being capped does not matter.
    lowest.capped, clearly.capped = True, False
    assert heldback.select([lowest, clearly], trust_capped=False) == ("ls", "search")


def test_one_minimum_found_three_times_is_one_candidate():
    data = _record()
    cost = PaperCost(ARX(2, 2, 1), data)
    theta = np.array([-1.5, 0.8, 0.5, 0.3])
    found = [
        heldback.Candidate("search", theta, 0.0, theta, 1.0),
        heldback.Candidate("ls", theta, 0.0, theta + 1e-12, 1.0),
        heldback.Candidate(
            "steiglitz-mcbride", theta, 0.0, theta + np.array([0.1, 0, 0, 0]), 1.0
        ),
    ]
    kept = heldback.distinct(found, cost)
    assert [c.name for c in kept] == ["search", "steiglitz-mcbride"]


def test_the_default_records_its_choice_among_its_whole_record_minima():
    est, val = _record(1, n=900, drift=0.01).split(2 / 3)
    fit = identify(est, ARX(4, 4, 1), rng=0, max_nfev=2000)
    sel = fit.selection
    assert sel is not None and sel["holdback"] == heldback.HOLDBACK
    assert sel["n_held"] == est.n - round(0.8 * est.n)
    chosen = next(c for c in sel["candidates"] if c["start"] == sel["chosen"])
    lowest = min(sel["candidates"], key=lambda c: c["cost"])
    assert sel["lowest_cost"] == lowest["start"]
    # The reported cost is the paper's over the whole estimation record:
    # that of the chosen minimum (before any cancellation).
    assert fit.result.get("fun_full", fit.cost) == pytest.approx(chosen["cost"])
    assert IdentifiedModel.from_dict(fit.to_dict()).selection == sel
    # The margin's own note, where it held a pole, follows the choice's, and
    # then what acting on the modes table did, where it acted (which, on
    # this drifting record, depends on the processor's last bits).
    notes = [sel["note"]] + [r["note"] for r in (fit.margin, fit.diagnosis) if r]
    assert validate(fit, val, warmup=est).choice == ". Then ".join(notes)
    # Only distinct minima are refitted and scored (one alone is not).
    held = [c["held_back_rms"] for c in sel["candidates"]]
    assert all((h is None) == (len(held) == 1) for h in held)


def test_holdback_none_chooses_by_the_cost_and_bad_shares_are_refused():
    est = _record(2)
    fit = identify(est, ARX(2, 2, 1), rng=0, max_nfev=1000, holdback=None)
    assert fit.selection is None
    for bad in (0.5, -0.1, "0.2", True):
        with pytest.raises(ValueError, match="`holdback` of method 'spiral'"):
            identify(est, ARX(2, 2, 1), rng=0, max_nfev=500, holdback=bad)


def test_a_record_too_short_to_hold_back_is_chosen_by_cost_and_says_so():
    est = _record(3, n=22)
    fit = identify(est, ARX(4, 4, 1), rng=0, max_nfev=500)
    assert fit.selection is None
    assert "too short to hold back" in fit.result.message


def test_a_single_minimum_is_chosen_without_a_refit():
    # One distinct minimum leaves nothing to choose: it is not refitted or
    # scored (held_back_rms None), and the note says so in words.
    theta = np.array([-1.5, 0.8, 0.5, 0.3])
    only = heldback.Candidate("ls", theta, None, theta, 1.0)
    assert heldback.select([only]) == ("ls", "ls")
    sel = heldback.Selection(0.2, 100, [only], "ls", "ls")
    assert sel.to_dict()["candidates"][0]["held_back_rms"] is None
    assert sel.sentence().startswith("1 distinct minimum")


def test_the_refits_are_capped_by_the_order():
    assert heldback.refit_nfev(8) == heldback.REFIT_NFEV * 9
    # A quarter of a full polish's default, 100 (p + 1).
    assert heldback.REFIT_NFEV == 25


def test_one_minimum_is_not_said_to_validate_best():
    # A single minimum is never scored on the held-back part, so the note
    # must not claim it was.
    only = heldback.Candidate("ls", np.zeros(2), None, np.zeros(2), 2.0)
    sel = heldback.Selection(0.2, 100, [only], *heldback.select([only]))
    assert sel.sentence() == (
        "1 distinct minimum (output error from least squares): nothing to "
        "choose on the held-back part"
    )
