"""Options of the public entry points: a default passed explicitly is
accepted, a wrong one is refused by its own name (issue 29's first cases)."""

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.optim import minimize_pareto


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(0)
    u = rng.standard_normal(400)
    return sid.IOData(u, lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u), ts=0.01)


def _two_objectives(x):
    return np.c_[x[:, 0], 1.0 - x[:, 0]]


def test_a_default_passed_by_value_is_the_default(record):
    # Equal, not the same object: float("1e6") is penalty's default.
    model = sid.identify(record, sid.NARX(2, 2, 1), method="ls", penalty=float("1e6"))
    assert model.structure == sid.NARX(2, 2, 1)
    with pytest.raises(ValueError, match="`penalty` does not apply to method 'ls' for"):
        sid.identify(record, sid.NARX(2, 2, 1), method="ls", penalty=1e5)


def test_the_spiral_method_s_rule_is_named_as_its_own_option(record):
    with pytest.raises(ValueError, match="`rule` of method 'spiral' must be one of"):
        sid.identify(record, sid.ARX(2, 2, 1), method="spiral", rule="nope")


def test_minimize_pareto_offers_only_the_rules_it_accepts():
    with pytest.raises(ValueError) as refused:
        minimize_pareto(_two_objectives, [(0, 1)] * 2, method="periodic")
    message = str(refused.value)
    assert "learned-metric" in message
    assert "periodic" not in message.split("; got")[0]
    assert "convergent" not in message


def test_minimize_pareto_checks_vectorized_as_minimize_does():
    with pytest.raises(ValueError, match="`vectorized` must be True or False"):
        minimize_pareto(_two_objectives, [(0, 1)] * 2, vectorized="yes")


# -- the contract, enumerated -------------------------------------------------

import re  # noqa: E402

import spiralid.sysid.estimation.identify as identify_module  # noqa: E402
import spiralid.sysid.estimation.narx as narx_module  # noqa: E402
from spiralid.cli import build_parser  # noqa: E402
from spiralid.cli.errors import UsageError  # noqa: E402
from spiralid.cli.identify import _OPTION_FLAGS, _check_options  # noqa: E402
from spiralid.sysid import METHODS  # noqa: E402
from spiralid.sysid.estimation.identify import (  # noqa: E402
    identify_options,
    refused_options,
)

STRUCTURES = {
    "arx": sid.ARX(2, 2, 1),
    "narx": sid.NARX(2, 2, 1, hidden=(3,)),
    "polynomial": sid.PolynomialNARX(2, 2, 1, degree=2, n_terms=4),
}
# A value other than the default for every option (validity is not the
# point: the option is refused or reaches the estimator before its value
# is checked).
NON_DEFAULT = {
    "predictor": "one-step",
    "initial": "measured",
    "rng": 1,
    "gain": 2.0,
    "penalty": 1e5,
    "integrator": 1,
    "max_time_constant": 5.0,
    "cancel": True,
    "parametrization": "reflection",
    "bounds": [[0.0, 1.0]],
    "refine": True,
    "safe_start": True,
    "holdout": 0.1,
    "decay": 0.01,
}
EVERY_OPTION = sorted(
    {
        name
        for method in METHODS
        for structure in STRUCTURES.values()
        for refine in (False, True)
        for name in identify_options(method, structure, refine)
    }
    | {"max_nfve", "polish_iterationz", "on_iteration"}
)
CASES = [
    (method, kind, option)
    for method in METHODS
    for kind in STRUCTURES
    if kind == "arx"
    or (METHODS[method].narx is not None and (kind == "narx" or method == "ls"))
    for option in EVERY_OPTION
]


class _Reached(Exception):
    """The options passed the contract and reached the estimator."""


def _reach(*args, **kwargs):
    raise _Reached


@pytest.fixture
def stop_before_estimating(monkeypatch):
    monkeypatch.setattr(identify_module, "_problem", _reach)
    monkeypatch.setattr(narx_module, "identify_narx", _reach)


@pytest.mark.parametrize(("method", "kind", "option"), CASES)
def test_every_method_option_pair_is_taken_or_refused_by_the_table(
    record, stop_before_estimating, method, kind, option
):
    structure = STRUCTURES[kind]
    value = NON_DEFAULT.get(option, 7)
    takes = option in identify_options(method, structure)
    if takes:
        with pytest.raises(_Reached):
            sid.identify(record, structure, method=method, **{option: value})
        return
    with pytest.raises(ValueError) as refused:
        sid.identify(record, structure, method=method, **{option: value})
    message = str(refused.value)
    assert "\n" not in message
    assert message.startswith(f"`{option}` does not apply to method '{method}'") or (
        "is now" in message and f"`{option}`" in message
    )


def _docstring_table() -> dict[str, set[str]]:
    """identify's Notes: the options each ARX method takes, as written."""
    doc = " ".join(sid.identify.__doc__.split())
    notes = doc[doc.index("Options by method") : doc.index("For a NARX structure")]
    common = {"predictor", "initial", "gain", "penalty", "integrator"}
    table = {}
    for bullet in notes.split(" - ")[1:]:
        heads, body = re.split(r'(?:"``|\)): ', bullet, maxsplit=1)
        names = set(re.findall(r"``(\w+)``", body)) | common
        for method in re.findall(r'``"([\w-]+)', heads + '"``'):
            table[method] = names
    rules = table.pop("sda")
    for method in METHODS:
        table.setdefault(method, rules)
    return table


@pytest.mark.parametrize("method", list(METHODS))
def test_the_docstring_says_what_each_method_takes(method):
    written = _docstring_table()[method]
    arx = STRUCTURES["arx"]
    taken = set(identify_options(method, arx, refine=True))
    assert written == taken


def _cli_args(method: str, kind: str, flag: str | None):
    argv = ["identify", "rig.csv", "--method", method, "--model", kind]
    if flag is not None:
        value = {
            "--predictor": "one-step",
            "--initial": "measured",
            "--seed": "1",
            "--integrator": "1",
            "--max-time-constant": "5",
            "--parametrization": "reflection",
            "--points": "7",
            "--iterations": "7",
            "--budget": "700",
            "--holdout": "0.1",
        }.get(flag)
        argv += [flag] if value is None else [flag, value]
    return build_parser().parse_args(argv)


@pytest.mark.parametrize(
    ("method", "kind", "flag"),
    [
        (method, kind, flag)
        for method in METHODS
        for kind in STRUCTURES
        if kind == "arx"
        or (METHODS[method].narx is not None and (kind == "narx" or method == "ls"))
        for flag in _OPTION_FLAGS
        if not (flag == "--integrator" and kind != "arx")
    ],
)
def test_the_command_refuses_what_python_refuses(method, kind, flag):
    args = _cli_args(method, kind, flag)
    name = _OPTION_FLAGS[flag]
    value = getattr(args, flag.removeprefix("--").replace("-", "_"))
    python_refuses = bool(refused_options(method, {name: value}, STRUCTURES[kind]))
    if python_refuses:
        with pytest.raises(UsageError, match=f"{flag} does not apply to --method"):
            _check_options(args)
    else:
        _check_options(args)
