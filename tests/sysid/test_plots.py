"""Plots return Figures with the expected content (smoke level) and never show."""

import matplotlib
import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from scipy import signal

from spiralid.sysid import ARX, IdentifiedModel, IOData, plots
from spiralid.sysid.spectra import find_resonances, modes_from_poles, psd
from spiralid.sysid.validation.correlation import independence_test, whiteness_test
from spiralid.sysid.validation.validate import validate

matplotlib.use("Agg")


@pytest.fixture(autouse=True)
def no_show(monkeypatch):
    import matplotlib.pyplot as plt

    def boom(*a, **k):
        raise AssertionError("plots must never call show()")

    monkeypatch.setattr(plt, "show", boom)


def test_time_response_overlays_models():
    t = np.arange(200) * 0.01
    y = np.sin(t)
    fig = plots.plot_time_response(t, y, {"SDA": y + 0.1, "Eb-SDA": y - 0.05})
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    top, err = fig.axes
    assert [ln.get_label() for ln in top.lines] == ["measured", "SDA", "Eb-SDA"]
    np.testing.assert_allclose(err.lines[0].get_ydata(), -0.1 * np.ones(200))
    assert len(plots.plot_time_response(t, y, y, error=False).axes) == 1
    with pytest.raises(ValueError, match="`outputs` must hold signals as long as `y`"):
        plots.plot_time_response(t, y, {"bad": y[:-1]})
    with pytest.raises(ValueError, match="`t` and `y` must have the same length"):
        plots.plot_time_response(t[:-1], y, y)


def test_residual_plot_has_stems_and_bands_per_level():
    rng = np.random.default_rng(0)
    u, e = rng.standard_normal(400), rng.standard_normal(400)
    w, c = whiteness_test(e, 10), independence_test(u, e, 10)
    fig = plots.plot_residual_tests(w, c)
    assert len(fig.axes) == 2
    # two levels -> four horizontal band lines per axes, at +-z/sqrt(N)
    bands = sorted(
        ln.get_ydata()[0] for ln in fig.axes[0].lines if ln.get_ls() != "None"
    )
    assert bands[-1] == pytest.approx(w.bands[0.99])
    assert bands[0] == pytest.approx(-w.bands[0.99])
    with pytest.raises(ValueError, match="`tests` must contain at least one"):
        plots.plot_residual_tests()
    with pytest.raises(ValueError, match="`tests` must be CorrelationTest objects"):
        plots.plot_residual_tests(w, "x")


def test_psd_plot_marks_peaks_and_modes():
    fs = 500.0
    t = np.arange(4096) / fs
    x = np.sin(2 * np.pi * 11.72 * t) + np.sin(2 * np.pi * 39.06 * t)
    s = psd(x, fs)
    pk = find_resonances(s, 2)
    z = np.exp((-1.0 + 2j * np.pi * 11.7) / fs)
    md = modes_from_poles([z, np.conj(z)], 1 / fs)
    fig = plots.plot_psd(s, {"model": psd(0.9 * x, fs)}, peaks=pk, modes={"model": md})
    (ax,) = fig.axes
    labels = [ln.get_label() for ln in ax.lines]
    assert labels[:2] == ["measured", "model"]
    # peak markers at the measured peaks, one vertical line per model mode
    np.testing.assert_allclose(ax.lines[2].get_xdata(), pk.frequency)
    assert len(ax.lines) == 4
    assert len(ax.texts) == 2
    with pytest.raises(ValueError, match="`measured` must be a PSD"):
        plots.plot_psd(x)


def test_pole_zero_map_with_unit_circle_and_several_models():
    fig = plots.plot_pole_zero(
        {"A": ([0.5 + 0.5j, 0.5 - 0.5j], [0.0]), "B": ([0.9], [-0.5, 0.2])}
    )
    (ax,) = fig.axes
    circle = ax.lines[0]
    r = np.hypot(circle.get_xdata(), circle.get_ydata())
    np.testing.assert_allclose(r, 1.0)
    assert [ln.get_label() for ln in ax.lines if not ln.get_label()[0] == "_"] == [
        "A poles",
        "A zeros",
        "B poles",
        "B zeros",
    ]
    assert ax.get_xlim() == pytest.approx((-1.15, 1.15))
    far = plots.plot_pole_zero({"A": ([0.5], [-47.0, 0.1])}).axes[0]
    assert far.get_xlim() == pytest.approx((-2.0, 2.0))
    assert "1 outside the view, largest |z| = 47" in far.get_title()
    with pytest.raises(ValueError, match="`radius` must be a finite number > 0"):
        plots.plot_pole_zero({"A": ([0.5], [])}, radius=0.0)
    with pytest.raises(TypeError, match="`models` must be a mapping"):
        plots.plot_pole_zero([0.5])
    with pytest.raises(ValueError, match="`models` values must be"):
        plots.plot_pole_zero({"A": 0.5})


def test_convergence_single_runs_and_median_band_over_seeds():
    h1 = np.geomspace(100, 1, 51)
    fig = plots.plot_convergence({"SDA": h1})
    assert len(fig.axes) == 1 and len(fig.axes[0].lines) == 1
    assert fig.axes[0].get_yscale() == "log"

    seeds = [np.geomspace(100, 1 + s, 51) for s in range(5)]
    fig = plots.plot_convergence(
        {"SDA": seeds, "Eb-SDA": [h[:40] for h in seeds]},
        times={"SDA": [1.0, 1.1, 1.2, 1.3, 1.4], "Eb-SDA": [2.0] * 5},
    )
    it_ax, time_ax = fig.axes
    assert time_ax.get_xlabel() == "wall time (s)"
    med = it_ax.lines[0]
    # median over seeds at each iteration, interquartile band shaded
    np.testing.assert_allclose(med.get_ydata(), np.median(np.vstack(seeds), axis=0))
    assert sum(isinstance(c, PolyCollection) for c in it_ax.collections) == 2
    assert "median of 5" in med.get_label()
    # per-entry times for a single run
    fig = plots.plot_convergence({"A": h1}, times={"A": np.linspace(0, 3, 51)})
    np.testing.assert_allclose(fig.axes[1].lines[0].get_xdata()[-1], 3.0)


def test_convergence_accepts_result_objects_and_rejects_bad_times():
    class Res:
        history = np.array([3.0, 2.0, 1.0])

    fig = plots.plot_convergence({"r": [Res(), Res()]}, log=False)
    assert fig.axes[0].get_yscale() == "linear"
    with pytest.raises(ValueError, match="`histories` must be a non-empty mapping"):
        plots.plot_convergence([1.0, 0.5])
    with pytest.raises(ValueError, match="`times` must be a mapping with the same"):
        plots.plot_convergence({"a": [1.0, 0.5]}, times={"b": 1.0})
    with pytest.raises(ValueError, match="`times` for 'a' must give one entry per"):
        plots.plot_convergence({"a": [[1.0, 0.5]] * 2}, times={"a": [1.0, 2.0, 3.0]})
    with pytest.raises(ValueError, match="`times` totals must be positive"):
        plots.plot_convergence({"a": [1.0, 0.5]}, times={"a": -1.0})


def test_validation_plot_gives_four_figures():
    wn, zeta, ts = 2 * np.pi * 11.72, 0.05, 0.002
    num, den, _ = signal.cont2discrete(([wn**2], [1, 2 * zeta * wn, wn**2]), ts)
    u = np.random.default_rng(0).standard_normal(1500)
    y = signal.lfilter(num.ravel(), den, u)
    theta = np.r_[den[1:], num.ravel()[1:]] * np.array([1, 1, 1.1, 1])
    m = IdentifiedModel(theta=theta, arx=ARX(2, 2, 1), ts=ts, method="test")
    figs = validate(m, IOData(u, y, ts=ts)).plot()
    assert set(figs) == {"time", "residuals", "spectrum", "pole_zero"}
    assert all(isinstance(f, Figure) for f in figs.values())
    assert [len(f.axes) for f in figs.values()] == [2, 2, 1, 1]


def test_residual_plot_adds_colour_adjusted_bands_for_coloured_signals():
    rng = np.random.default_rng(0)
    u = signal.lfilter([1.0], [1.0, -0.9], rng.standard_normal(2000))
    e = signal.lfilter([1.0], [1.0, -0.7], rng.standard_normal(2000))
    c = independence_test(u, e, 10)
    assert c.band_scale > 1.5
    (ax,) = plots.plot_residual_tests(c).axes
    labels = [ln.get_label() for ln in ax.lines]
    assert "95 % band, colour-adjusted" in labels


def test_plot_validations_overlays_models_on_one_record():
    wn, zeta, ts = 2 * np.pi * 11.72, 0.05, 0.002
    num, den, _ = signal.cont2discrete(([wn**2], [1, 2 * zeta * wn, wn**2]), ts)
    u = np.random.default_rng(0).standard_normal(1000)
    data = IOData(u, signal.lfilter(num.ravel(), den, u), ts=ts)
    theta = np.r_[den[1:], num.ravel()[1:]]
    vals = {
        name: validate(
            IdentifiedModel(theta=theta * k, arx=ARX(2, 2, 1), ts=ts, method=name),
            data,
        )
        for name, k in (("SDA", [1, 1, 1.2, 1]), ("Eb-SDA", [1, 1, 1.05, 1]))
    }
    figs = plots.plot_validations(vals)
    assert set(figs) == {"time", "spectrum", "pole_zero"}
    top = figs["time"].axes[0]
    assert [ln.get_label() for ln in top.lines] == ["measured", "SDA", "Eb-SDA"]
    figs = plots.plot_validations(list(vals.values()), fmax=100.0)
    assert figs["spectrum"].axes[0].get_xlim()[1] == 100.0
    other = validate(
        IdentifiedModel(theta=theta, arx=ARX(2, 2, 1), ts=ts, method="x"),
        IOData(u[:500], data.y[:500], ts=ts),
    )
    with pytest.raises(
        ValueError, match="`validations` must all be on the same record"
    ):
        plots.plot_validations([vals["SDA"], other])
    with pytest.raises(ValueError, match="`validations` must hold at least one"):
        plots.plot_validations([])


def test_importing_the_library_does_not_import_matplotlib():
    import subprocess
    import sys

    code = (
        "import sys, spiralid, spiralid.sysid as s\n"
        "assert not any(m.startswith('matplotlib') for m in sys.modules)\n"
        "s.plots\n"
        "assert 'matplotlib' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_figures_carry_units_continue_time_and_label_residuals():
    from scipy.signal import lfilter

    from spiralid.sysid import ARX, IOData, identify, validate

    u = np.random.default_rng(0).standard_normal(600)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    data = IOData(u, y, ts=0.01, output_name="accel", output_unit="m/s^2")
    est, val = data.split(0.5)
    v = validate(identify(est, ARX(2, 2, 1), method="ls"), val, warmup=est)
    figs = v.plot()
    top, err = figs["time"].axes
    assert top.get_ylabel() == "accel (m/s^2)"
    assert err.get_ylabel().endswith("(m/s^2)")
    # The validation part continues the record's time axis after the warm-up.
    assert top.lines[0].get_xdata()[0] == pytest.approx(300 * 0.01)
    for ax in figs["residuals"].axes:
        assert ax.get_ylabel() == "normalised correlation"
        legend = ax.get_legend()
        assert legend is not None and legend.get_bbox_to_anchor().x0 > 0


def test_log_cost_axis_keeps_several_labelled_ticks():
    from spiralid.sysid.validation.plots import plot_convergence

    # Costs within less than a decade: plain log ticks would label one value.
    h = [np.linspace(90.0, 60.0, 40), np.linspace(95.0, 70.0, 40)]
    fig = plot_convergence({"SDA": h}, cost_label="best cost (%)")
    ax = fig.axes[0]
    fig.canvas.draw()
    lo, hi = ax.get_ylim()
    labels = [
        t.get_text()
        for t in ax.get_yticklabels()
        if t.get_text() and lo <= t.get_position()[1] <= hi
    ]
    assert len(labels) >= 3, labels
    assert ax.get_ylabel() == "best cost (%)"
