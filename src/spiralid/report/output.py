"""Write a reproduction to disk: PNG figures, ``results.json``, ``report.html``.

The output folder must be new or empty unless ``force`` is given; with
``force`` the files this module writes are replaced and nothing else in the
folder is touched. The files are written atomically
(:class:`~spiralid.outputs.atomic.OutputFolder`): all of them or none.
"""

from __future__ import annotations

import html
import json
import platform
from pathlib import Path

import numpy as np

from spiralid.outputs.atomic import OutputFolder
from spiralid.report.html import figure, page, png, table
from spiralid.reproduction import HEADLINE_TEST, Reproduction
from spiralid.sysid.models.polynomials import format_pole_radius

__all__ = [
    "HEADLINE_TEST",
    "OUTPUT_FILES",
    "headline",
    "results_dict",
    "summary_text",
    "verdict",
    "write_reproduction",
]

OUTPUT_FILES = ("results.json", "report.html")
# What the report names as its command when it was not given one.
REPRODUCE_CALL = "spiralid.reproduction.reproduce()"

# The numbers the paper reports in Table-2, shown beside ours.
PAPER_TABLE2 = {
    "SDA": (35.85, (-0.1159, 0.1074), (-0.1355, 0.1458)),
    "Eb-SDA": (17.83, (-0.0614, 0.0638), (-0.0642, 0.0629)),
}


def versions() -> dict:
    import matplotlib
    import numba
    import scipy

    import spiralid

    return {
        "spiralid": spiralid.__version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "matplotlib": matplotlib.__version__,
        "platform": platform.platform(),
        # The numbers depend on it: each OpenBLAS kernel rounds its own way.
        "blas_kernel": blas_kernel(),
    }


def blas_kernel() -> str:
    """The OpenBLAS kernel NumPy runs on (e.g. ``"Haswell"``), ``"unknown"``
    where it cannot be asked (another BLAS, no ``/proc``)."""
    import ctypes

    try:
        with open("/proc/self/maps", encoding="utf-8") as fh:
            path = next(line.split()[-1] for line in fh if "openblas" in line)
        lib = ctypes.CDLL(path)
    except (OSError, StopIteration, IndexError):
        return "unknown"
    for name in (
        "scipy_openblas_get_corename64_",
        "scipy_openblas_get_corename",
        "openblas_get_corename64_",
        "openblas_get_corename",
    ):
        getter = getattr(lib, name, None)
        if getter is not None:
            getter.restype = ctypes.c_char_p
            return getter().decode("ascii", "replace")
    return "unknown"


# The experiment's verdicts are the Reproduction's to compute; these names
# stay for callers of the report's module.
headline = Reproduction.headline
verdict = Reproduction.verdict


def results_dict(rep: Reproduction, command: str | None = None) -> dict:
    """Every number of the reproduction, JSON-safe."""
    data = rep.data
    best = {label: rep.best(label) for label in [*rep.runs, *rep.baselines]}
    return {
        "command": command,
        "versions": versions(),
        "elapsed_seconds": rep.elapsed,
        "data": {
            **rep.source,
            "input": data.input_name,
            "output": data.output_name,
            "input_unit": data.input_unit,
            "output_unit": data.output_unit,
            "n_samples": data.n,
            "ts": data.ts,
            "n_estimation": rep.estimation.n,
            "n_validation": rep.validation.n,
        },
        "structure": {"na": rep.arx.na, "nb": rep.arx.nb, "nk": rep.arx.nk},
        "seeds": rep.seeds,
        "options": {**rep.options, "penalty": _penalty(rep)},
        "rules": _rules(),
        "search_bounds": _bounds(rep),
        "configurations": [
            {
                "label": c.label,
                "method": c.method,
                "parametrization": c.parametrization,
                "gain_scale": c.gain_scale,
                "refine": c.refine,
                "safe_start": c.safe_start,
            }
            for c in rep.configurations
        ],
        "table2": rep.table2(),
        "paper_table2": {
            k: {"best_fitness": v[0], "modelling": v[1], "validation": v[2]}
            for k, v in PAPER_TABLE2.items()
        },
        "statistics": {label: rep.statistics(label) for label in rep.runs},
        "ranksum": rep.ranksums(),
        "verdict": rep.verdict(),
        "headline_test": rep.headline(),
        "verdict_by_budget": rep.budget_verdict(),
        "transfer_functions": {k: r.model.tf_string(digits=4) for k, r in best.items()},
        "validation": {
            k: {"estimation": e.to_dict(), "validation": v.to_dict()}
            for k, (e, v) in rep.validations.items()
        },
        "baselines": {k: r.to_dict() for k, r in rep.baselines.items()},
        "runs": {k: [r.to_dict() for r in runs] for k, runs in rep.runs.items()},
        # Only with reproduce(all_outputs=True), so that the paper's run
        # writes the paper's keys alone.
        **(
            {}
            if rep.shared is None
            else {
                "modes_from_every_sensor": {
                    **rep.shared.to_dict(),
                    "comparison": rep.modes_comparison(),
                }
            }
        ),
    }


def _penalty(rep: Reproduction) -> float:
    return float(next(iter(rep.baselines.values())).model.penalty)


def _rules() -> dict:
    """The radius and angle rules' constants (SDA, eq. (7)-(8), linear...)."""
    from dataclasses import asdict

    from spiralid.optim import RULES

    return {name: asdict(rule()) for name, rule in RULES.items()}


def _bounds(rep: Reproduction) -> dict:
    """The search box of each parametrisation, from the first run using it."""
    out = {}
    for c in rep.configurations:
        bounds = rep.runs[c.label][0].model.bounds
        if c.parametrization not in out and bounds is not None:
            out[c.parametrization] = np.asarray(bounds).tolist()
    return out


def _range(r) -> str:
    return f"[{r[0]:.4g}, {r[1]:.4g}]"


def _table2_rows(rep: Reproduction) -> list[list]:
    return [
        [
            row["label"],
            f"{row['best_fitness']:.4g}",
            _range(row["error_range_modelling"]),
            _range(row["error_range_validation"]),
            f"{row['fit_validation_percent']:.1f}",
        ]
        for row in rep.table2()
    ]


_T2_HEAD = [
    "method",
    "best fitness",
    "error range (modelling)",
    "error range (validation)",
    "validation fit %",
]


def _t2_head(unit: str) -> list[str]:
    """Table-2's header, its error ranges in the output's unit when known."""
    if not unit:
        return _T2_HEAD
    return [h.replace(")", f", {unit})") if "range" in h else h for h in _T2_HEAD]


_STAT_HEAD = [
    "method",
    "mean",
    "std",
    "median",
    "best",
    "worst",
    "median val. fit %",
]


def _stat_rows(rep: Reproduction) -> list[list]:
    rows = []
    for label in rep.runs:
        s = rep.statistics(label)
        rows.append(
            [
                label,
                *(
                    f"{s[k]:.4g}"
                    for k in (
                        "cost_mean",
                        "cost_std",
                        "cost_median",
                        "cost_best",
                        "cost_worst",
                    )
                ),
                f"{s['fit_val_median']:.1f}",
            ]
        )
    for label, run in rep.baselines.items():
        rows.append(
            [label, f"{run.cost:.4g}", "-", "-", "-", "-", f"{run.fit_val:.1f}"]
        )
    return rows


def summary_text(rep: Reproduction) -> str:
    """Table-2, the statistics over seeds and the verdict, as plain text."""
    d = rep.options
    return "\n".join(
        [
            f"{rep.arx} on {rep.data.output_name} ({rep.data.n} samples, ts = "
            f"{rep.data.ts:g} s; estimation {rep.estimation.n}, validation "
            f"{rep.validation.n}); {len(rep.seeds)} seeds, {d['max_nfev']} cost "
            f"evaluations per run (refine adds its own), {d['n_points']} points, "
            f"simulation from {d['initial']}.",
            "",
            "Table-2 (best run of each method; cost = eq. (2), % of rms(y))",
            table(_t2_head(rep.data.output_unit), _table2_rows(rep)),
            "",
            "Estimation cost over seeds",
            table(_STAT_HEAD, _stat_rows(rep)),
            "",
            rep.verdict(),
            f"Headline test: {HEADLINE_TEST}.",
            rep.budget_verdict()["sentence"],
            *_every_sensor_text(rep),
            f"Experiment wall time {rep.elapsed:.1f} s.",
        ]
    )


def _every_sensor_text(rep: Reproduction) -> list[str]:
    """The modes from every sensor beside the FEM's, for the summary (none
    without ``all_outputs``)."""
    from spiralid.report.shared_output import every_sensor_lines

    return [] if rep.shared is None else ["", *every_sensor_lines(rep.shared)]


def _tf_block(label: str, tf: str) -> str:
    """``"(B) / (A)"`` as three lines: the label, B(z) and A(z)."""
    parts = tf.split(" / ")
    if len(parts) != 2:
        return f"{label}:\n  H(z) = {tf}\n"
    num, den = (p[1:-1] if p[:1] == "(" and p[-1:] == ")" else p for p in parts)
    return f"{label}:\n  B(z) = {num}\n  A(z) = {den}\n"


def _html(rep: Reproduction, images: dict[str, bytes], command: str | None) -> str:
    parts = [
        _INTRO,
        _setup_section(rep, command),
        _verdict_section(rep),
        _table2_section(rep),
        _statistics_section(rep),
        *_figures(rep, images),
        _transfer_functions_section(rep),
        _stability_section(rep),
        _modes_section(rep),
        _every_sensor_section(rep),
        _READING,
    ]
    return page("spiralid: SDA vs Eb-SDA reproduction", parts)


_INTRO = (
    "<h1>SDA vs exponential-based SDA: ARX modelling of a flexible "
    "manipulator</h1>"
    "<p>A reproduction of the results section of Nasir, Ismail, Ahmad and "
    "Tokhi, <i>Exponential-based spiral dynamic algorithm for modelling of a "
    "flexible manipulator system</i>, with the statistics over seeds the paper "
    "lacks and least-squares (LS) and output-error (OE) baselines beside the "
    "metaheuristics.</p>"
)


def _setup_section(rep: Reproduction, command: str | None) -> str:
    """The command, the record, the model and the budget."""
    e = html.escape
    d = rep.options
    start = "rest" if d["initial"] == "rest" else "the measured first samples"
    return (
        f"<p>Command: <code>{e(command or REPRODUCE_CALL)}</code><br>"
        f"Data: {e(rep.data.input_label)} &rarr; {e(rep.data.output_label)}, "
        f"{rep.data.n} samples at ts = {rep.data.ts:g} s; first "
        f"{rep.estimation.n} to estimate, last {rep.validation.n} to validate.<br>"
        f"Model: {e(str(rep.arx))}, predictor: free-run simulation from "
        f"{start}, gain w = {d['gain']:.4g} (cost = 100 rms(e)/rms(y)).<br>"
        f"Budget: {d['max_nfev']} cost evaluations per run, {d['n_points']} "
        f"points, seeds {rep.seeds}; the local polish of '+ refine' adds its own "
        f"evaluations. Experiment wall time {rep.elapsed:.1f} s.</p>"
    )


def _verdict_section(rep: Reproduction) -> str:
    """The headline verdict, its test and the budget ladder's sentence."""
    e = html.escape
    return (
        f"<h2>Verdict</h2><p><b>{e(rep.verdict())}</b></p>"
        f"<p>Headline test: {e(HEADLINE_TEST)}.</p>"
        f"<p>{e(rep.budget_verdict()['sentence'])}</p>"
    )


def _table2_section(rep: Reproduction) -> str:
    """Table-2 of this run beside the paper's own."""
    paper = [
        [k, f"{v[0]:g}", _range(v[1]), _range(v[2])] for k, v in PAPER_TABLE2.items()
    ]
    return (
        "<h2>Table-2</h2><p>Best run of each method (lowest estimation cost). "
        "Error ranges are min and max of the free-run error y - y&#770; in "
        "output units.</p>"
        + table(_t2_head(rep.data.output_unit), _table2_rows(rep), "html")
        + "<p>The paper's Table-2, on its own rig and record (its gain w is not "
        "stated, so its fitness scale is unknown):</p>"
        + table(_T2_HEAD[:4], paper, "html")
    )


def _statistics_section(rep: Reproduction) -> str:
    """The cost over seeds and the rank-sum test of each pair."""
    e = html.escape
    tests = "".join(
        f"<li>{e(t['a'])} vs {e(t['b'])}: two-sided p = {t['p_two_sided']:.3g}, "
        f"A12 = {t['a12']:.2f}</li>"
        for t in rep.ranksums()
    )
    return (
        "<h2>Statistics over seeds</h2><p>Estimation cost (eq. (2) at the "
        "default gain) of every run; the headline's two-sided rank-sum test "
        "of Eb-SDA against SDA, per parametrisation:</p>"
        + table(_STAT_HEAD, _stat_rows(rep), "html")
        + f"<ul>{tests}</ul>"
    )


def _figure_captions(shown: str) -> dict[str, tuple[str, str]]:
    """Each figure's title and caption, `shown` naming the configurations
    drawn."""
    return {
        "fig6a_convergence": (
            "Figure 6a: convergence",
            "Best cost against iteration and wall time: median over seeds with "
            "the interquartile band. Left the paper's pair on its own scale; "
            f"right {shown} on a log scale, with the LS and OE costs as dashed "
            "reference lines.",
        ),
        "fig6bc_estimation": (
            "Figures 6b-c: modelling part",
            f"Measured output against the best {shown} and OE models (free run), "
            "and their errors; OE dashed, so a curve it lies on shows between "
            "the dashes.",
        ),
        "fig7ab_validation": (
            "Figures 7a-b: validation part",
            f"The best {shown} and OE models run over the whole record; the "
            "validation third and its errors are shown, OE dashed.",
        ),
        "fig7c_spectrum": (
            "Figure 7c: power spectral density",
            f"Validation output, measured and of the best {shown} and OE models: "
            "measured peaks labelled, model modes as dotted lines.",
        ),
        "pole_zero": ("Pole-zero map", f"The best {shown} models."),
        "distributions": (
            "Every run",
            "Estimation cost and validation fit per configuration, with LS and "
            "OE as dashed reference lines under the boxes, named at the right "
            "edge. The 'w x 0.1' and 'w x 10' boxes show how "
            "Eb-SDA moves when the unstated gain of eq. (2) is scaled (their "
            "costs rescored at the default gain).",
        ),
    }


def _figures(rep: Reproduction, images: dict[str, bytes]) -> list[str]:
    """Each PNG with its title and caption (its stem alone when unknown)."""
    from spiralid.report.figures import figure_labels

    captions = _figure_captions(", ".join(figure_labels(rep, baselines=False)))
    out = []
    for stem, data in images.items():
        title, caption = captions.get(stem, (stem, ""))
        out.append(figure(title, data, caption))
    return out


def _transfer_functions_section(rep: Reproduction) -> str:
    """Each best model's and baseline's B(z) / A(z)."""
    # One block per model, numerator and denominator each on its own line;
    # the page's CSS wraps a line longer than the column.
    blocks = "".join(
        html.escape(_tf_block(label, rep.best(label).model.tf_string()))
        for label in [*rep.runs, *rep.baselines]
    )
    return (
        "<h2>Transfer functions (form of eq. (9)-(10))</h2><p>H(z) = B(z) / A(z) "
        f"of each method's best run and of the baselines.</p><pre class='tf'>"
        f"{blocks}</pre>"
    )


_STABILITY_HEAD = [
    "model",
    "stable",
    "max |pole|",
    "controllable",
    "observable",
    "min |p - z|",
    "model modes (Hz)",
    "measured peaks (Hz)",
]


def _stability_section(rep: Reproduction) -> str:
    """Stability, controllability and observability of each validated model."""
    rows = []
    for label, (_, v) in rep.validations.items():
        r = v.realization
        rows.append(
            [
                label,
                "yes" if v.stable else "NO",
                format_pole_radius(v.max_pole_radius),
                "yes" if r.controllable else "no",
                "yes" if r.observable else "no",
                f"{r.min_pole_zero_distance:.3g}",
                ", ".join(f"{f:.2f}" for f in v.modes.frequency[:4]),
                ", ".join(f"{f:.2f}" for f in v.peaks_measured.frequency),
            ]
        )
    return "<h2>Stability, controllability, observability</h2>" + table(
        _STABILITY_HEAD, rows, "html"
    )


_READING = (
    "<h2>How we read the paper</h2><ul>"
    "<li>Cost, eq. (2)-(3): f = w sqrt(sum e^2) / K plus a penalty of 1e6 "
    "when a pole has |z| &ge; 1; w is not given, so w = 100 sqrt(K) / rms(y) "
    "makes f the percentage RMS error.</li>"
    "<li>The predicted output is the free-run simulation from the input "
    "alone.</li>"
    "<li>Eb-SDA, eq. (7)-(8): r = (0.1 - 1)/(1 + 100/exp(1.5 d)) + 1 and "
    "&theta; = (0.1 - 2)/(1 + 10/exp(d)) + 2 with d = |f(x_i) - min J|; a "
    "random draw when d = 0. SDA: r = 0.95, &theta; = &pi;/4.</li>"
    "<li>Initial denominators are drawn stable (uniform reflection "
    "coefficients); the paper's runs search raw coefficients with the "
    "penalty, the '(reflection)' rows search reflection coefficients.</li>"
    "<li>2/3 of the record estimates, 1/3 validates; validation fit is "
    "MATLAB's compare fit of the free run.</li>"
    "<li>Stable means every pole has |z| &lt; 1, decided by the Schur-Cohn "
    "test on the coefficients (the penalty's test, margin zero), the same "
    "verdict everywhere; a radius within 1e-4 of the circle is printed as "
    "its distance from 1.</li></ul>"
)


def _modes_section(rep: Reproduction) -> str:
    """Each best model's modes with their 95 % intervals (from the
    estimate's covariance, ``IdentifiedModel.modes``) and flags."""
    rows = []
    for label in [*rep.runs, *rep.baselines]:
        model = rep.best(label).model
        if getattr(model, "covariance", None) is None:
            continue
        table_ = model.modes
        f_int, d_int = table_.frequency_interval, table_.damping_interval
        for i in range(len(table_)):
            rows.append(
                [
                    label,
                    f"{table_.frequency[i]:.4g}",
                    f"[{f_int[i, 0]:.4g}, {f_int[i, 1]:.4g}]",
                    f"{table_.damping[i]:.4f}",
                    f"[{d_int[i, 0]:.4f}, {d_int[i, 1]:.4f}]",
                    f"{100 * table_.share[i]:.1f}",
                    "; ".join(table_.notes(i)),
                ]
            )
    if not rows:
        return ""
    return (
        "<h2>Modes with 95 % intervals</h2><p>Each best model's complex pole "
        "pairs as modes; the intervals come from the estimate's covariance "
        "s<sup>2</sup> (J<sup>T</sup>J)<sup>-1</sup> by the delta method, and "
        "the share is the mode's resonant peak as a part of the model's.</p>"
        + table(
            [
                "model",
                "frequency (Hz)",
                "95 % interval (Hz)",
                "damping",
                "95 % interval",
                "share (%)",
                "flags",
            ],
            rows,
            "html",
        )
    )


def _every_sensor_section(rep: Reproduction) -> str:
    """The rig's modes from all four sensors (``all_outputs``): the shared
    modes' table, each output's fit and the modes beside the FEM's and the
    single-output models'."""
    from spiralid.report.shared_output import every_sensor_section

    if rep.shared is None:
        return ""
    return every_sensor_section(
        rep.shared,
        rep.modes_comparison(),
        "the paper's single-output models (best run of each configuration, "
        "end-point acceleration alone) and the baselines",
    )


def write_reproduction(
    rep: Reproduction,
    out: str | Path | OutputFolder,
    *,
    force: bool = False,
    command: str | None = None,
) -> list[Path]:
    """Write figures (PNG), ``results.json`` and ``report.html`` into `out`.

    Parameters
    ----------
    rep : Reproduction
    out : path-like or OutputFolder
        The target folder, or an open :class:`OutputFolder` (the command
        line opens it before computing, so a locked or unwritable target is
        refused before the experiment runs).
    force : bool
        Write into a non-empty folder (ignored for an open OutputFolder).
    command : str, optional
        The command line recorded in the report.

    Returns
    -------
    list of Path
        The files written, at their final place.
    """
    if isinstance(out, OutputFolder):
        return _write_files(rep, out, command)
    with OutputFolder(out, force) as folder:
        return _write_files(rep, folder, command)


def _write_files(rep: Reproduction, folder: OutputFolder, command) -> list[Path]:
    from spiralid.report.figures import all_figures

    images = {}
    for stem, fig in all_figures(rep).items():
        images[stem] = png(fig)
        (folder.path / f"{stem}.png").write_bytes(images[stem])
    results = json.dumps(results_dict(rep, command), indent=2, allow_nan=True)
    (folder.path / "results.json").write_text(results)
    (folder.path / "report.html").write_text(
        _html(rep, images, command), encoding="utf-8"
    )
    return folder.commit(last="report.html")
