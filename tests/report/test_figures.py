"""The reproduction's figures: every one shows the recommended method beside
the paper's two, the baselines where it has references, and keeps its
legend and reference lines off the data."""

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid import ARX, IOData
from spiralid.report.figures import all_figures, figure_labels, recommended
from spiralid.reproduction import Configuration, reproduce

CONFIGS = (
    Configuration("SDA", "sda"),
    Configuration("Eb-SDA", "ebsda"),
    Configuration("spiral (recommended)", "spiral", "modal"),
)


@pytest.fixture(scope="module")
def rep():
    rng = np.random.default_rng(7)
    u = rng.standard_normal(600)
    y = lfilter([0.0, 0.5, 0.25], [1.0, -1.2, 0.5], u) + 0.01 * rng.standard_normal(600)
    return reproduce(
        IOData(u, y, ts=0.01),
        seeds=2,
        max_nfev=200,
        n_points=10,
        arx=ARX(2, 2, 1),
        configurations=CONFIGS,
        workers=1,
    )


@pytest.fixture(scope="module")
def figures(rep):
    return all_figures(rep)


def _legend_labels(fig) -> list[str]:
    """Every legend text of `fig`: its axes', its own and its subfigures'."""
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes)]
    for sub in fig.subfigs:
        legends += sub.legends
    return [t.get_text() for lg in legends if lg is not None for t in lg.get_texts()]


def _shows(labels, name) -> bool:
    # "SDA" must not be found in "Eb-SDA ...": a label starts with the name.
    return any(label == name or label.startswith(name + " ") for label in labels)


def test_the_recommended_method_is_found(rep):
    assert recommended(rep) == ["spiral (recommended)"]
    assert figure_labels(rep) == ["SDA", "Eb-SDA", "spiral (recommended)", "OE"]


def test_every_figure_shows_the_recommended_method_beside_the_paper_pair(figures):
    assert set(figures) == {
        "fig6a_convergence",
        "fig6bc_estimation",
        "fig7ab_validation",
        "fig7c_spectrum",
        "pole_zero",
        "distributions",
    }
    for stem, fig in figures.items():
        if stem == "distributions":
            # One box per configuration, named on the axis.
            ticks = [t.get_text() for t in fig.axes[-1].get_xticklabels()]
            assert ticks == [c.label for c in CONFIGS], ticks
            continue
        labels = _legend_labels(fig)
        for name in ("SDA", "Eb-SDA", "spiral (recommended)"):
            assert _shows(labels, name), (stem, name, labels)


@pytest.mark.parametrize(
    "stem",
    ["fig6a_convergence", "fig6bc_estimation", "fig7ab_validation", "fig7c_spectrum"],
)
def test_figures_with_references_show_the_baselines(figures, stem):
    labels = _legend_labels(figures[stem])
    assert "OE" in labels, labels
    if stem == "fig6a_convergence":
        assert "LS" in labels, labels


def test_legends_sit_outside_the_axes(figures):
    for stem, fig in figures.items():
        assert all(ax.get_legend() is None for ax in fig.axes), stem
        assert fig.legends, stem


def test_reference_lines_lie_under_the_boxes(figures):
    fig = figures["distributions"]
    for ax in fig.axes:
        refs = [line for line in ax.get_lines() if line.get_label() in ("LS", "OE")]
        assert {line.get_label() for line in refs} == {"LS", "OE"}
        boxes = [line for line in ax.get_lines() if line.get_label().startswith("_")]
        assert boxes
        under = max(line.get_zorder() for line in refs)
        assert under < min(line.get_zorder() for line in boxes)
        assert all(line.get_linestyle() == "--" for line in refs)
        # Each reference named at the axes' right edge.
        names = {t.get_text() for t in ax.texts}
        assert {"LS", "OE"} <= names


def test_figures_without_the_recommended_method(rep):
    """Under initial="measured" reproduce leaves the recommended method out:
    the figures show the paper's pair and the baselines."""
    from dataclasses import replace

    without = replace(
        rep,
        configurations=CONFIGS[:2],
        runs={k: v for k, v in rep.runs.items() if k in ("SDA", "Eb-SDA")},
    )
    assert recommended(without) == []
    figs = all_figures(without)
    for stem in ("fig6bc_estimation", "pole_zero"):
        labels = _legend_labels(figs[stem])
        assert not any("spiral" in label for label in labels), labels
        assert _shows(labels, "Eb-SDA")
