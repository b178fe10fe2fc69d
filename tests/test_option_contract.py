"""Options of the public entry points: a default passed explicitly is
accepted, a wrong one is refused by its own name (issue 29's first cases)."""

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.optim import Restarts, minimize, minimize_pareto


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
    with pytest.raises(TypeError, match="`vectorized` must be True or False"):
        minimize_pareto(_two_objectives, [(0, 1)] * 2, vectorized="yes")


# -- the contract, enumerated -------------------------------------------------

import re  # noqa: E402

import spiralid.sysid.estimation.core.arx_fit as arx_fit_module  # noqa: E402
import spiralid.sysid.estimation.narx.training as narx_module  # noqa: E402
from spiralid.cli import build_parser  # noqa: E402
from spiralid.cli.errors import UsageError  # noqa: E402
from spiralid.cli.identify import _OPTION_FLAGS, _check_options  # noqa: E402
from spiralid.sysid import METHODS  # noqa: E402
from spiralid.sysid.estimation.core.families import ESTIMATORS  # noqa: E402
from spiralid.sysid.estimation.core.identify import (  # noqa: E402
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
    "noise": "integrated",
    "parametrization": "reflection",
    "bounds": [[0.0, 1.0]],
    "refine": True,
    "safe_start": True,
    "holdout": 0.1,
    "decay": 0.01,
    "training": "subsequences",
    "horizon": 50,
}
EVERY_OPTION = sorted(
    {
        name
        for method in METHODS
        for structure in STRUCTURES.values()
        if (structure.family, method) in ESTIMATORS
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
    or (("narx", method) in ESTIMATORS and (kind == "narx" or method == "ls"))
    for option in EVERY_OPTION
]


class _Reached(Exception):
    """The options passed the contract and reached the estimator."""


def _reach(*args, **kwargs):
    raise _Reached


@pytest.fixture
def stop_before_estimating(monkeypatch):
    monkeypatch.setattr(arx_fit_module, "_problem", _reach)
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
    # The common ones, read from the sentence that names them.
    head = notes[: notes.index("which every method takes")]
    common = set(re.findall(r"``(\w+)``", head))
    assert common == {"rng", "predictor", "initial", "gain", "penalty", "integrator"}
    notes = notes[len(head) :]
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
            "--noise": "integrated",
            "--folds": "on",
            "--training": "subsequences",
            "--horizon": "12",
            "--workers": "2",
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
        or (("narx", method) in ESTIMATORS and (kind == "narx" or method == "ls"))
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


# -- the misuse matrix: real calls, one-line errors naming the option ---------

ARX2 = sid.ARX(2, 2, 1)
NARX2 = sid.NARX(2, 2, 1, hidden=(3,))
POLY = sid.PolynomialNARX(2, 2, 1, degree=2, n_terms=4)
_IDENTIFY_MISUSE = [
    # issue 29's cases
    (ARX2, dict(method="ls", refine=True), "refine"),
    (ARX2, dict(method="ls", safe_start=True), "safe_start"),
    (ARX2, dict(method="oe", bounds=[(0, 1)] * 4), "bounds"),
    (ARX2, dict(method="ls", parametrization="modal"), "parametrization"),
    (ARX2, dict(method="oe", parametrization="modal"), "parametrization"),
    (ARX2, dict(method="oe", refine=True), "refine"),
    (ARX2, dict(method="oe", safe_start=False), "safe_start"),
    (ARX2, dict(method="ls", n_points=10), "n_points"),
    (ARX2, dict(method="ls", max_nfev=100), "max_nfev"),
    (ARX2, dict(method="ls", max_iter=5), "max_iter"),
    (ARX2, dict(method="oe", callback=print), "callback"),
    (ARX2, dict(method="ls", holdback=0.3), "holdback"),
    (ARX2, dict(method="oe", rule="sda"), "rule"),
    (ARX2, dict(method="ls", max_time_constant=1.0), "max_time_constant"),
    (ARX2, dict(method="ls", cancel=True), "cancel"),
    (ARX2, dict(method="sda", max_time_constant=1.0), "max_time_constant"),
    (ARX2, dict(method="ebsda", cancel=False), "cancel"),
    (ARX2, dict(method="de", cancel=True), "cancel"),
    (ARX2, dict(method="de", target=1.0), "target"),
    (ARX2, dict(method="de", restarts=True), "restarts"),
    (ARX2, dict(method="de", bounds_policy="clip"), "bounds_policy"),
    (ARX2, dict(method="spiral", target=1.0), "target"),
    (ARX2, dict(method="spiral", max_nfve=100), "max_nfve"),
    (ARX2, dict(method="spiral", bounds_policy="clip"), "bounds_policy"),
    (ARX2, dict(method="spiral", restart_after=10), "restart_after"),
    (ARX2, dict(method="spiral", polish_iterations=3), "polish_iterations"),
    (ARX2, dict(method="sda", holdback=0.1), "holdback"),
    (ARX2, dict(method="sda", polish_every=3), "polish_every"),
    (ARX2, dict(method="ebsda", rule="sda"), "rule"),
    (ARX2, dict(method="ls", holdout=0.1), "holdout"),
    (ARX2, dict(method="ls", decay=0.1), "decay"),
    (ARX2, dict(method="sda", on_iteration=print), "on_iteration"),
    (
        ARX2,
        dict(method="spiral", restarts=Restarts(tol_radius=1e-3)),
        "restarts.tol_radius",
    ),
    # NARX structures
    (NARX2, dict(method="ls", penalty=1e5), "penalty"),
    (NARX2, dict(method="ls", gain=2.0), "gain"),
    (NARX2, dict(method="oe", refine=True), "refine"),
    (NARX2, dict(method="oe", bounds=[(0, 1)]), "bounds"),
    (NARX2, dict(method="oe", cancel=True), "cancel"),
    (NARX2, dict(method="oe", max_time_constant=1.0), "max_time_constant"),
    (NARX2, dict(method="ls", parametrization="modal"), "parametrization"),
    (NARX2, dict(method="ls", integrator=True), "integrator"),
    (NARX2, dict(method="ls", max_rnds=3), "max_rnds"),
    (NARX2, dict(method="oe", n_points=10), "n_points"),
    (NARX2, dict(method="spiral", holdback=0.1), "holdback"),
    (NARX2, dict(method="spiral", restarts=True), "restarts"),
    (NARX2, dict(method="spiral", polish_iterations=3), "polish_iterations"),
    (NARX2, dict(method="sda", safe_start=True), "safe_start"),
    (NARX2, dict(method="de"), "method"),
    (POLY, dict(method="ls", holdout=0.3), "holdout"),
    (POLY, dict(method="ls", max_rounds=3), "max_rounds"),
    (POLY, dict(method="ls", holdout=0.1), "holdout"),
]


@pytest.mark.parametrize(
    ("structure", "kwargs", "option", "error"),
    [
        # The budget rule copies max_nfev into max_iter: max_nfev is named.
        (ARX2, dict(method="sda", max_nfev="1000"), "max_nfev", TypeError),
        (ARX2, dict(method="de", max_nfev=1000.0), "max_nfev", TypeError),
        (ARX2, dict(method="sda", max_nfev=0), "max_nfev", ValueError),
        (ARX2, dict(method="spiral", max_nfev="1000"), "max_nfev", TypeError),
        (ARX2, dict(method="spiral", n_points=2.5), "n_points", TypeError),
        (ARX2, dict(method="sda", n_points="x"), "n_points", TypeError),
        (NARX2, dict(method="sda", max_nfev="1000"), "max_nfev", TypeError),
        # The NARX spiral's rule is its `rule`, not minimize's `method`.
        (NARX2, dict(method="spiral", rule="x"), "rule", ValueError),
        (NARX2, dict(method="spiral", max_iter="x"), "max_iter", TypeError),
    ],
)
def test_an_error_names_the_argument_passed(record, structure, kwargs, option, error):
    with pytest.raises((TypeError, ValueError)) as refused:
        sid.identify(record, structure, **kwargs)
    assert refused.type is error
    assert str(refused.value).startswith(f"`{option}` must be")


@pytest.mark.parametrize(("structure", "kwargs", "option"), _IDENTIFY_MISUSE)
def test_identify_misuse_is_one_line_naming_the_option(
    record, structure, kwargs, option
):
    with pytest.raises(ValueError) as refused:
        sid.identify(record, structure, **kwargs)
    message = str(refused.value)
    assert "\n" not in message and f"`{option}`" in message


@pytest.mark.parametrize("method", ["ls", "oe", "spiral"])
def test_rng_is_accepted_by_every_method_so_one_call_loops_over_them(record, method):
    # A documented acceptance (identify's `rng`): ls and oe have nothing to
    # seed, and give the same model with any seed.
    options = {"max_nfev": 300} if method == "spiral" else {}
    first = sid.identify(record, ARX2, method=method, rng=0, **options)
    again = sid.identify(record, ARX2, method=method, rng=0, **options)
    np.testing.assert_array_equal(first.theta, again.theta)
    if method != "spiral":
        other = sid.identify(record, ARX2, method=method, rng=1)
        np.testing.assert_array_equal(first.theta, other.theta)


_PARETO_MISUSE = [
    (dict(max_iter=5), "max_iter"),
    (dict(polish_nfev=10), "polish_nfev"),
    (dict(objectives=("cost", "one-step"), nperseg=64), "nperseg"),
    (dict(objectives=("cost", "one-step"), fmin=1.0), "fmin"),
    (dict(objectives=("cost", "one-step"), min_coherence=0.3), "min_coherence"),
    (dict(refine=True), "refine"),
    (dict(restarts=True), "restarts"),
    (dict(x0=[0.0]), "x0"),
    (dict(extremes_nfev=-1), "extremes_nfev"),
    (dict(seed_estimates="yes"), "seed_estimates"),
]


@pytest.mark.parametrize(("kwargs", "option"), _PARETO_MISUSE)
def test_identify_pareto_misuse_is_one_line_naming_the_option(record, kwargs, option):
    with pytest.raises((TypeError, ValueError)) as refused:
        sid.identify_pareto(record, ARX2, rng=0, **kwargs)
    message = str(refused.value)
    assert "\n" not in message and f"`{option}`" in message


def test_identify_pareto_accepts_frequency_defaults_without_the_objective(record):
    front = sid.identify_pareto(
        record, ARX2, ("cost", "one-step"), rng=0, max_nfev=200, n_points=10,
        extremes_nfev=0, min_coherence=0.5, nperseg=None,
    )  # fmt: skip
    assert front.names == ("cost", "one-step")


@pytest.fixture(scope="module")
def narx_model(record):
    est, _ = record.split(2 / 3)
    return sid.identify(est, NARX2, method="ls", rng=0)


@pytest.mark.parametrize(
    ("kwargs", "option"),
    [
        (dict(n_peaks=4, nperseg=64, max_damping=0.9), "max_damping"),
        (dict(max_damping=0.9), "max_damping"),
    ],
)
def test_validate_refuses_the_modes_option_for_a_narx_model(
    record, narx_model, kwargs, option
):
    # Modes are read from poles, which a NARX model does not have; its
    # spectra and their peaks (n_peaks, nperseg) are computed as for ARX.
    _, val = record.split(2 / 3)
    with pytest.raises(ValueError) as refused:
        sid.validate(narx_model, val, **kwargs)
    message = str(refused.value)
    assert "\n" not in message and f"`{option}` does not apply" in message


def test_validate_accepts_the_defaults_for_a_narx_model(record, narx_model):
    _, val = record.split(2 / 3)
    report = sid.validate(narx_model, val, n_peaks=3, max_damping=float("0.3"))
    assert np.isfinite(report.fit_percent)
    spectra = sid.validate(narx_model, val, n_peaks=1, nperseg=64)
    assert (
        spectra.psd_measured.nperseg == 64 and spectra.peaks_model.frequency.size <= 1
    )


@pytest.mark.parametrize(
    ("call", "option"),
    [
        (lambda: minimize(np.sum, [(0, 1)] * 2, callbak=print), "callbak"),
        (lambda: minimize(np.sum, [(0, 1)] * 2, restarts=3), "restarts"),
        (
            lambda: minimize_pareto(_two_objectives, [(0, 1)] * 2, method="periodic"),
            "method",
        ),
        (
            lambda: minimize_pareto(_two_objectives, [(0, 1)] * 2, vectorized="yes"),
            "vectorized",
        ),
    ],
)
def test_optimiser_misuse_is_one_line_naming_the_option(call, option):
    with pytest.raises((TypeError, ValueError)) as refused:
        call()
    message = str(refused.value)
    assert "\n" not in message and option in message


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(method="ls", refine=False),
        dict(method="ls", safe_start=None),
        dict(method="ls", parametrization=None),
        dict(method="ls", max_time_constant="auto"),
        dict(method="ls", cancel=None),
        dict(method="ls", rng=None),
        dict(method="ls", penalty=float("1e6")),
        dict(method="oe", holdout=0.2),
    ],
)
def test_a_default_passed_by_value_is_accepted(record, kwargs):
    model = sid.identify(record, ARX2, **kwargs)
    assert model.method == kwargs["method"]


# -- no public function takes more than 12 parameters -------------------------

import dataclasses  # noqa: E402
import importlib  # noqa: E402
import inspect  # noqa: E402
import pkgutil  # noqa: E402

MAX_PARAMETERS = 12


def _public_callables():
    """Every function, and every public method and non-record constructor of
    a class, named in the `__all__` of spiralid and its public modules.
    Dataclasses are records: their constructor's parameters are their
    fields, not a call's settings."""
    modules = [sid] + [
        importlib.import_module(info.name)
        for info in pkgutil.walk_packages(sid.__path__, "spiralid.")
        if not any(part.startswith("_") for part in info.name.split("."))
    ]
    for module in modules:
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if inspect.isclass(obj):
                members = [
                    (f"{obj.__qualname__}.{attr}", getattr(obj, attr))
                    for attr, value in vars(obj).items()
                    if not attr.startswith("_")
                    and inspect.isfunction(getattr(value, "__func__", value))
                ]
                if not dataclasses.is_dataclass(obj):
                    members.append((obj.__qualname__, obj.__init__))
                yield from members
            elif inspect.isfunction(obj):
                yield f"{obj.__module__}.{obj.__qualname__}", obj


def _parameters(function) -> int:
    """Parameters in the signature, self and cls aside: a **kwargs (one
    mapping of a method's options) and an *args count as one each."""
    return sum(
        1
        for p in inspect.signature(function).parameters.values()
        if p.name not in ("self", "cls")
    )


def test_no_public_function_takes_more_than_12_parameters():
    counted = dict(_public_callables())
    assert "spiralid.optim.spiral.minimize" in counted
    over = {
        name: _parameters(function)
        for name, function in counted.items()
        if _parameters(function) > MAX_PARAMETERS
    }
    assert not over, over


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: minimize(np.sum, [(0, 1)], target=1.0), "target"),
        (lambda: minimize(np.sum, [(0, 1)], max_time=1.0), "max_time"),
        (lambda: minimize(np.sum, [(0, 1)], bounds_policy="clip"), "bounds_policy"),
        (
            lambda: minimize_pareto(_two_objectives, [(0, 1)], neighbours=5),
            "neighbours",
        ),
        (
            lambda: minimize_pareto(_two_objectives, [(0, 1)], ref_point=[2, 2]),
            "ref_point",
        ),
        (
            lambda: minimize_pareto(_two_objectives, [(0, 1)], "sda", max_iter=5),
            "max_iter",
        ),
    ],
)
def test_a_keyword_the_optimiser_does_not_take_is_one_line_naming_it(call, name):
    # A key of `options` is not a keyword: Python's own TypeError names it.
    with pytest.raises(TypeError) as refused:
        call()
    message = str(refused.value)
    assert "\n" not in message
    assert message.endswith(f"() got an unexpected keyword argument {name!r}")


def test_an_options_key_that_does_not_apply_is_named_with_those_that_do():
    with pytest.raises(ValueError) as refused:
        minimize_pareto(_two_objectives, [(0, 1)], options={"neighbors": 5})
    assert str(refused.value) == (
        "`neighbors` does not apply to the options of minimize_pareto(); the "
        "options that do: max_time, neighbours, ref_point"
    )
    same = minimize_pareto(
        _two_objectives, [(0, 1)], n_points=10, max_nfev=40, rng=0,
        vectorized=True, options={"neighbours": 10, "max_time": None},
    )  # fmt: skip
    again = minimize_pareto(
        _two_objectives, [(0, 1)], n_points=10, max_nfev=40, rng=0, vectorized=True
    )
    np.testing.assert_array_equal(same.x, again.x)


# -- identify_pareto's contract, enumerated -----------------------------------

import spiralid.sysid.estimation.pareto.identify as pareto_module  # noqa: E402
from spiralid.cli.pareto import _OPTION_FLAGS as _PARETO_FLAGS  # noqa: E402
from spiralid.cli.pareto import _check_options as _check_pareto  # noqa: E402
from spiralid.optim.pareto import PARETO_METHODS  # noqa: E402
from spiralid.sysid.estimation.pareto.options import (  # noqa: E402
    pareto_options,
    refused_pareto_options,
)

OBJECTIVE_SETS = [
    ("cost", "frequency"),
    ("cost", "one-step"),
    ("frequency", "one-step"),
    ("cost", "frequency", "one-step"),
]
# A valid value other than the default for every option: an option that
# applies must reach the search, past its own value's checks.
PARETO_NON_DEFAULT = {
    "n_points": 12,
    "max_nfev": 300,
    "max_time": 100.0,
    "neighbours": 5,
    "parametrization": "coefficients",
    "seed_estimates": False,
    "extremes_nfev": 7,
    "nperseg": 64,
    "fmin": 1.0,
    "fmax": 10.0,
    "min_coherence": 0.3,
}
EVERY_PARETO_OPTION = sorted(
    {name for names in OBJECTIVE_SETS for name in pareto_options(names)}
    | {"max_iter", "polish_nfev", "ref_point", "archive", "nperseq"}
)


@pytest.fixture
def stop_before_searching(monkeypatch):
    monkeypatch.setattr(pareto_module, "_search_structure", _reach)


@pytest.mark.parametrize(
    ("method", "objectives", "option"),
    [
        (method, objectives, option)
        for method in PARETO_METHODS
        for objectives in OBJECTIVE_SETS
        for option in EVERY_PARETO_OPTION
    ],
)
def test_every_pareto_option_is_taken_or_refused_by_the_table(
    record, stop_before_searching, method, objectives, option
):
    value = PARETO_NON_DEFAULT.get(option, 7)
    call = dict(method=method, rng=0, **{option: value})
    if option in pareto_options(objectives):
        with pytest.raises(_Reached):
            sid.identify_pareto(record, ARX2, objectives, **call)
        return
    with pytest.raises(ValueError) as refused:
        sid.identify_pareto(record, ARX2, objectives, **call)
    message = str(refused.value)
    assert "\n" not in message
    assert message.startswith(
        f"`{option}` does not apply to identify_pareto with method '{method}' "
        f"and objectives {objectives}; the options that do: "
    ) or message.startswith(f"`{option}` of identify_pareto is now")


@pytest.mark.parametrize("objectives", OBJECTIVE_SETS)
def test_identify_pareto_accepts_every_option_at_its_default(
    record, stop_before_searching, objectives
):
    # Every option's default, the frequency objective's among them.
    defaults = pareto_options(("cost", "frequency", "one-step"))
    assert refused_pareto_options(objectives, defaults) == []
    with pytest.raises(_Reached):
        sid.identify_pareto(record, ARX2, objectives, rng=0, **defaults)


def _pareto_args(objectives, flag):
    value = {
        "--points": "7",
        "--budget": "700",
        "--parametrization": "coefficients",
        "--polish": "7",
        "--min-coherence": "0.3",
    }.get(flag)
    argv = ["pareto", "rig.csv", "--objectives", ",".join(objectives)]
    argv += [flag] if value is None else [flag, value]
    return build_parser().parse_args(argv)


@pytest.mark.parametrize(
    ("objectives", "flag"),
    [(objectives, flag) for objectives in OBJECTIVE_SETS for flag in _PARETO_FLAGS],
)
def test_the_pareto_command_refuses_what_python_refuses(objectives, flag):
    args = _pareto_args(objectives, flag)
    name = _PARETO_FLAGS[flag]
    value = (
        not args.no_seeds
        if name == "seed_estimates"
        else getattr(args, flag[2:].replace("-", "_"))
    )
    if refused_pareto_options(objectives, {name: value}):
        with pytest.raises(UsageError) as refused:
            _check_pareto(args)
        assert str(refused.value).startswith(
            f"{flag} does not apply to --objectives {','.join(objectives)}; "
            "the options that do: "
        )
    else:
        _check_pareto(args)
