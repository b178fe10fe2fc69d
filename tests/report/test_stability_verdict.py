"""One stability verdict: is_stable, validate, results.json and the report agree,
and agree with an exact (rational) Schur-Cohn test of the model's coefficients."""

from fractions import Fraction

import numpy as np
import pytest
from scipy import signal

from spiralid.report.output import _html, results_dict
from spiralid.reproduction import Configuration, reproduce
from spiralid.sysid import ARX, IdentifiedModel, IOData, validate
from spiralid.sysid.estimation.core import estimators
from spiralid.sysid.models.polynomials import format_pole_radius

# The best Eb-SDA (w x 0.1) model of a default `spiralid reproduce` run: a
# pole pair within 1e-15 of the unit circle. numpy.roots puts it at
# |z| = 1.0, so validate called it unstable while is_stable (and the cost's
# penalty) called it stable, and the report printed "1.0000000, NO".
MARGINAL = np.array(
    [0.09984729491880823, 0.3757056511081378, -0.8735584972235871,
     -0.8433466465353396, -0.635874422871492, 0.21011139645472118,
     0.3230661249342037, 0.7920119764646781, -4.6025551579535495,
     -46.4808264673243, 57.4862584663411, -40.9595529616953, 39.56183501914038,
     12.118133263918743, 32.512086724524465, 5.710938687608722]
)  # fmt: skip
ARX8 = ARX(8, 8, 0)


def _exactly_stable(a) -> bool:
    """Schur-Cohn step-down in exact rational arithmetic on the float
    coefficients: every |k_j| < 1."""
    work = [Fraction(float(v)) for v in a]
    for j in range(len(work) - 1, -1, -1):
        k = work[j]
        if abs(k) >= 1:
            return False
        work = [(work[i] - k * work[j - 1 - i]) / (1 - k * k) for i in range(j)]
    return True


def _outside(theta, rho):
    """The same model with every pole scaled by rho."""
    return np.r_[theta[:8] * rho ** np.arange(1, 9), theta[8:]]


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(600)
    y = signal.lfilter([0.0, 0.5, 0.25], [1.0, -1.2, 0.5], u)
    return IOData(u, y + 0.01 * rng.standard_normal(u.size), ts=0.002)


@pytest.mark.parametrize(("rho", "stable"), [(1.0, True), (1.0 + 1e-6, False)])
def test_is_stable_and_validate_agree_with_the_exact_test(data, rho, stable):
    theta = _outside(MARGINAL, rho)
    assert _exactly_stable(theta[:8]) is stable
    model = IdentifiedModel(theta, ARX8, data.ts, method="ebsda")
    v = validate(model, data)
    assert model.is_stable is v.stable is stable
    assert (model.max_pole_radius < 1) is (v.max_pole_radius < 1) is stable
    text = format_pole_radius(v.max_pole_radius)
    assert text.startswith("1 - " if stable else "1 + ")
    row = next(r for r in v.summary().splitlines() if r.startswith("stable"))
    assert row.endswith(f"  {stable} ({text})")


def _fixed(theta):
    def estimate(problem, **_options):
        return estimators.EstimatorResult(
            x=theta, fun=float(problem.cost(theta)), status=0, message="fixed",
            nfev=0, nit=0, history=None, elapsed=0.0,
        )  # fmt: skip

    # It stands in for a search, so it takes a spiral method's options
    # (reproduce passes the same budget to every configuration).
    return estimators.Method(estimate, options=estimators.METHODS["sda"].options)


def test_results_json_and_the_report_say_the_same(data, monkeypatch):
    monkeypatch.setitem(estimators.METHODS, "marginal", _fixed(MARGINAL))
    monkeypatch.setitem(
        estimators.METHODS, "unstable", _fixed(_outside(MARGINAL, 1 + 1e-6))
    )
    rep = reproduce(
        data,
        seeds=1,
        max_nfev=100,
        n_points=10,
        arx=ARX8,
        configurations=(
            Configuration("Marginal", "marginal"),
            Configuration("Unstable", "unstable"),
        ),
        workers=1,
    )
    results = results_dict(rep)
    html = _html(rep, {}, None)
    page = html[html.index("Stability, controllability") :]
    for label, stable in (("Marginal", True), ("Unstable", False)):
        run = results["runs"][label][0]
        val = results["validation"][label]["validation"]
        assert run["stable"] is val["stable"] is stable
        assert (run["max_pole_radius"] < 1) is (val["max_pole_radius"] < 1) is stable
        row = page[page.index(f"<td>{label}</td>") :].split("</tr>")[0]
        cells = row.replace("</td>", "").split("<td>")
        assert cells[2] == ("yes" if stable else "NO")
        assert cells[3] == format_pole_radius(val["max_pole_radius"])
        assert cells[3].startswith("1 - " if stable else "1 + ")
