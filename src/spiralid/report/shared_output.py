"""The report of a model of several outputs (one denominator).

``spiralid identify --output a,b,...`` writes ``report.html`` from
:func:`write_shared_report`: the shared modes with their 95 % intervals and
each one's share in each output, the modes' shapes over the outputs and
their MAC matrix, every output's fit on both parts and the
joint fit, each output's validation figures, and a stabilisation diagram
over a range of orders. The numbers are computed in :mod:`spiralid.sysid`
(the model's ``modes``, ``validate``, ``stabilisation``); this
module only lays them out. The "modes from every sensor" section of the
reproduction's and the study's reports (:func:`every_sensor_section`,
:func:`every_sensor_lines`) uses the same tables (:func:`modes_table`,
:func:`fit_percents_table`).

Matplotlib is imported only when a figure is drawn.
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from spiralid.report.html import figure, page, png, table
from spiralid.sysid.models.modes import interval_format

__all__ = [
    "every_sensor_lines",
    "every_sensor_section",
    "fit_percents_table",
    "fits_table",
    "mac_table",
    "modes_table",
    "output_stems",
    "shapes_table",
    "shared_report",
    "write_shared_report",
]


def _num(value: float, fmt: str) -> str:
    """`value` in `fmt`, or "-" where it is not finite (no interval: the
    method gives no covariance)."""
    return format(value, fmt) if np.isfinite(value) else "-"


def _interval(pair, fmt: str) -> str:
    lo, hi = pair
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return "-"
    return f"[{lo:{fmt}}, {hi:{fmt}}]"


def modes_table(modes) -> tuple[list[str], list[list[str]]]:
    """The header and rows of a :class:`~spiralid.sysid.SharedModes`: each
    mode's frequency (Hz) and damping ratio with their 95 % intervals (to as
    many digits as tell the interval's ends apart, four at least), its
    share (%) of each output's resonant peaks and its flags.

    Parameters
    ----------
    modes : SharedModes
        ``model.modes`` of a shared-denominator model.

    Returns
    -------
    header : list of str
    rows : list of list of str
    """
    t = modes.table
    pct = round(100 * t.level)
    header = [
        "mode",
        "frequency (Hz)",
        f"{pct} % interval (Hz)",
        "damping",
        f"{pct} % interval",
        *(f"share in {name} (%)" for name in modes.output_names),
        "flags",
    ]
    f_int, d_int = t.frequency_interval, t.damping_interval
    rows = []
    for i in range(len(t)):
        f_fmt = interval_format(f_int[i])
        d_fmt = interval_format(d_int[i], "f")
        rows.append(
            [
                str(i + 1),
                _num(t.frequency[i], f_fmt),
                _interval(f_int[i], f_fmt),
                _num(t.damping[i], d_fmt),
                _interval(d_int[i], d_fmt),
                *(_num(100 * s, ".1f") for s in modes.share[i]),
                "; ".join(t.notes(i)),
            ]
        )
    return header, rows


def shapes_table(shapes) -> tuple[list[str], list[list[str]]]:
    """The header and rows of a :class:`~spiralid.sysid.models.shapes.ModeShapes`:
    each mode's frequency and each output's normalised component (real
    part, unit norm, the largest positive) with its 95 % interval's half
    width; the imaginary parts, small for a lightly damped mode, are left
    to the model's ``shapes``.

    Parameters
    ----------
    shapes : ModeShapes
        ``model.shapes`` of a shared-denominator model.

    Returns
    -------
    header : list of str
    rows : list of list of str
    """
    pct = round(100 * shapes.level)
    header = [
        "mode",
        "frequency (Hz)",
        *(f"{name} [+- {pct} %]" for name in shapes.output_names),
    ]
    half = shapes.real_interval[..., 1] - shapes.shapes.real
    rows = [
        [
            str(r + 1),
            f"{shapes.frequency[r]:.4g}",
            *(
                f"{shapes.shapes[r, i].real:+.3f}"
                + (f" +- {half[r, i]:.3f}" if np.isfinite(half[r, i]) else "")
                for i in range(len(shapes.output_names))
            ),
        ]
        for r in range(len(shapes))
    ]
    return header, rows


def mac_table(matrix) -> tuple[list[str], list[list[str]]]:
    """The header and rows of a MAC matrix (modes numbered from 1).

    Parameters
    ----------
    matrix : array_like, shape (m, k)
        MAC values, e.g. ``model.shapes.auto_mac``.

    Returns
    -------
    header : list of str
    rows : list of list of str
    """
    matrix = np.asarray(matrix, dtype=float)
    header = ["MAC", *(str(k + 1) for k in range(matrix.shape[1]))]
    rows = [[str(i + 1), *(f"{v:.3f}" for v in row)] for i, row in enumerate(matrix)]
    return header, rows


def fits_table(v_est, v_val) -> tuple[list[str], list[list[str]]]:
    """The header and rows of each output's free-run fit (%) on the
    estimation and validation parts, and the joint fit last.

    Parameters
    ----------
    v_est, v_val : Validation
        :func:`~spiralid.sysid.validate` on the two parts (each output's
        and the joint fit).

    Returns
    -------
    header : list of str
    rows : list of list of str
    """

    def numbers(v) -> dict:
        return {
            "outputs": {name: o.fit_percent for name, o in v.outputs.items()},
            "joint": v.fit_percent,
            "diverged": [name for name, o in v.outputs.items() if o.diverged],
        }

    return fit_percents_table(
        {"estimation": numbers(v_est), "validation": numbers(v_val)}
    )


def fit_percents_table(fits: dict) -> tuple[list[str], list[list[str]]]:
    """:func:`fits_table` from the numbers alone (what a study's store
    keeps of the validations).

    Parameters
    ----------
    fits : dict
        :func:`spiralid.study.modes.fit_percents`: per part
        (``"estimation"``, ``"validation"``) the ``"outputs"``' fits (%),
        the ``"joint"`` fit and the outputs whose free run ``"diverged"``.

    Returns
    -------
    header : list of str
    rows : list of list of str
    """
    est, val = fits["estimation"], fits["validation"]

    def fit(part: dict, name: str) -> str:
        flag = " (diverged)" if name in part["diverged"] else ""
        return f"{part['outputs'][name]:.2f}{flag}"

    rows = [[name, fit(est, name), fit(val, name)] for name in val["outputs"]]
    rows.append(["joint", f"{est['joint']:.2f}", f"{val['joint']:.2f}"])
    return ["output", "fit % (estimation)", "fit % (validation)"], rows


def every_sensor_section(
    fit, comparison: list[dict], models: str, title: str = "Modes from every sensor"
) -> str:
    """The HTML section of the rig's modes from every sensor: the shared
    modes' table, each output's fit, and the modes beside the FEM's and the
    single-output models'.

    Parameters
    ----------
    fit : SharedModesFit
        :class:`spiralid.study.modes.SharedModesFit`.
    comparison : list of dict
        :func:`spiralid.study.modes.modes_comparison` of `fit` (its rows
        after the FEM's).
    models : str
        What the single-output models of `comparison` are, in words.
    title : str
        The section's heading.

    Returns
    -------
    str
    """
    from spiralid.study.modes import MODE_WINDOW

    e = html.escape
    model = fit.model
    head = ["model", "structure"]
    for i in range(1, fit.fem_hz.size + 1):
        head += [f"mode {i} (Hz)", "error (%)"]
    rows = [
        [
            f"FEM (rig.modes({fit.fem_hz.size}))",
            "-",
            *(c for f in fit.fem_hz for c in (f"{f:.4f}", "-")),
        ]
    ]
    for row in comparison:
        cells = [row["model"], row["structure"]]
        for f, err in zip(row["frequency_hz"], row["error_percent"], strict=True):
            cells += ["-", "-"] if f is None else [f"{f:.4f}", f"{err:+.4f}"]
        rows.append(cells)
    integrators = ", ".join(
        f"{n} {k}" for n, k in zip(model.output_names, model.integrators, strict=True)
    )
    return (
        f"<h2>{e(title)}</h2><p>The same simulated run's four sensors "
        f"({e(', '.join(model.output_names))}) identified with one "
        f"denominator, {e(str(model.arx))} by {e(model.method)} (seed "
        f"{fit.seed}, {fit.seconds:.1f} s), known integrators outside the "
        f"shared poles: {e(integrators)}. The 95 % intervals come from the "
        "shared denominator's covariance; a share is the mode's resonant peak "
        "as a part of that output's.</p>"
        + table(*modes_table(model.modes), "html")
        + table(*fit_percents_table(fit.fits), "html")
        + "<p>Each model's mode nearest each of the finite-element model's "
        f"first {fit.fem_hz.size} natural frequencies, and its error: the shared "
        f"fit beside {e(models)}; - where the model has no mode within "
        f"{100 * MODE_WINDOW:g} % of the FEM's.</p>" + table(head, rows, "html")
    )


def every_sensor_lines(fit, title: str = "Modes from every sensor") -> list[str]:
    """The modes from every sensor beside the FEM's, as lines of text (a
    summary's paragraph, the modes' table last).

    Parameters
    ----------
    fit : SharedModesFit
        :class:`spiralid.study.modes.SharedModesFit`.
    title : str
        The paragraph's first words.

    Returns
    -------
    list of str
    """
    model = fit.model
    hz, err = fit.nearest(model.modes.table.frequency)
    fem = ", ".join(f"{f:.4g}" for f in fit.fem_hz)
    found = ", ".join(
        f"{f:.4g} ({e:+.4f} %)" if np.isfinite(f) else "none"
        for f, e in zip(hz, err, strict=True)
    )
    return [
        f"{title} ({', '.join(model.output_names)}; {model.arx}, integrators "
        f"{', '.join(map(str, model.integrators))}): {found} against the FEM's "
        f"{fem} Hz; joint validation fit {fit.fits['validation']['joint']:.2f} %.",
        str(model.modes),
    ]


_FIGURE_CAPTIONS = {
    "time": "Measured output and the free run of its transfer function B_i / A "
    "over the validation part (run on from the estimation part), and the error.",
    "spectrum": "Power spectral density of the measured and the model's output "
    "on the validation part, measured peaks labelled, the shared modes as "
    "dotted lines.",
    "residuals": "Whiteness of the residuals and their independence of the "
    "input, with the 95 % and 99 % bands and each test's verdict.",
    "pole_zero": "The shared poles (and this output's known integrators) with "
    "this output's zeros.",
}


def _figures(v_val, diagram, data):
    """The stabilisation diagram's figure (None without one) and each
    output's validation figures, by output name, each figure as ``stem ->
    (title, PNG, caption)``."""
    diagram_figure = None
    if diagram is not None:
        from spiralid.sysid.validation.mode_plots import plot_stabilisation

        orders = ", ".join(str(n) for n in diagram.orders)
        diagram_figure = (
            "Each order's modes over the record's spectra",
            png(plot_stabilisation(diagram, data)),
            f"Orders na = {orders}.",
        )
    stems = output_stems(v_val.outputs)
    by_output = {
        name: {
            f"validation_{stems[name]}_{kind}": (
                f"{name}: {kind.replace('_', '-')}",
                png(fig),
                _FIGURE_CAPTIONS.get(kind, ""),
            )
            for kind, fig in v.plot().items()
        }
        for name, v in v_val.outputs.items()
    }
    return diagram_figure, by_output


def output_stems(names) -> dict[str, str]:
    """Each output's name as a file-name part (letters, digits, _ and -),
    one per name and told apart: how its figures are named, by ``identify
    --output`` and ``validate``.

    Two names that become the same part ("acc x" and "acc.x", or two that
    differ only in case, which some file systems do not tell apart) get
    ``-2``, ``-3``... after the later ones.

    Parameters
    ----------
    names : iterable of str
        The outputs' names, each once.

    Returns
    -------
    dict of str to str
        Each name's part, in the order of `names`.

    Examples
    --------
    >>> output_stems(["acc x", "acc.x", "tip"])
    {'acc x': 'acc_x', 'acc.x': 'acc_x-2', 'tip': 'tip'}
    """
    out: dict[str, str] = {}
    taken: set[str] = set()
    for name in names:
        kept = "".join(c if c.isalnum() or c in "_-" else "_" for c in name)
        stem, k = kept or "output", 1
        while stem.casefold() in taken:
            k += 1
            stem = f"{kept or 'output'}-{k}"
        taken.add(stem.casefold())
        out[name] = stem
    return out


def shared_report(
    model,
    v_est,
    v_val,
    *,
    headline: str,
    diagram=None,
    data=None,
    stabilisation_note: str = "",
    command: str | None = None,
) -> tuple[str, dict[str, bytes]]:
    """The HTML page of a shared-denominator model and its figures.

    Parameters
    ----------
    model : SharedDenominatorModel
    v_est, v_val : Validation
        The validations on the estimation and validation parts.
    headline : str
        The page's first line (what was identified on which record).
    diagram : StabilisationDiagram, optional
        Drawn with :func:`~spiralid.sysid.plots.plot_stabilisation`.
    data : IOData, optional
        The record whose spectra the diagram draws behind the modes.
    stabilisation_note : str
        How the diagram's orders were identified (its caption).
    command : str, optional
        The command line recorded in the page.

    Returns
    -------
    html : str
        The page, figures embedded.
    images : dict of str to bytes
        Each figure as PNG, by file-name stem.
    """
    e = html.escape
    diagram_figure, by_output = _figures(v_val, diagram, data)
    m_head, m_rows = modes_table(model.modes)
    f_head, f_rows = fits_table(v_est, v_val)
    integrators = ", ".join(
        f"{name} {k}"
        for name, k in zip(model.output_names, model.integrators, strict=True)
    )
    parts = [
        f"<h1>{e(headline)}</h1>",
        f"<p>Command: <code>{e(command)}</code></p>" if command else "",
        f"<p>One denominator of {model.arx.na} poles for "
        f"{model.n_outputs} outputs, a numerator each ({e(str(model.arx))}); "
        f"method {e(model.method)}, joint cost (weighted, % RMS) "
        f"{_num(model.cost, '.6g')}. Known integrators outside the shared poles: "
        f"{e(integrators)}.</p>",
        "<h2>Shared modes</h2><p>The complex pole pairs of the shared "
        "denominator, with 95 % intervals from its covariance (variable "
        "projection, the numerators projected out); a share is the mode's "
        "resonant peak as a part of that output's peaks (after its known "
        "integrators are taken out): a sensor near a node of a mode barely "
        "sees it. An interval shown as - has no covariance behind it.</p>",
        table(m_head, m_rows, "html"),
        *_shapes_parts(model),
        "<h2>Fits</h2><p>Free-run fit (MATLAB's compare fit) of each output's "
        "transfer function on the estimation part and, run on from it, the "
        "validation part; the joint fit is 100 (1 - sqrt(mean_i (1 - "
        "fit_i / 100)<sup>2</sup>)).</p>",
        table(f_head, f_rows, "html"),
    ]
    if diagram_figure is not None:
        title, data_png, caption = diagram_figure
        note = stabilisation_note or caption
        parts.append(
            "<h2>Stabilisation diagram</h2>"
            + figure(
                title,
                data_png,
                note + " A mode is stable when the order below has one within "
                f"{100 * diagram.frequency_tolerance:g} % in frequency and "
                f"{100 * diagram.damping_tolerance:g} % in damping.",
            )
        )
    images = {} if diagram_figure is None else {"stabilisation": diagram_figure[1]}
    for name, figures in by_output.items():
        parts.append(f"<h2>Validation of {e(name)}</h2>")
        for stem, (title, data_png, caption) in figures.items():
            parts.append(figure(title, data_png, caption))
            images[stem] = data_png
    return page(headline, parts), images


def _shapes_parts(model) -> list[str]:
    """The report's mode shapes and MAC matrix (none without modes), one
    set per input of a model of several inputs."""
    names = model.input_names
    if len(names) == 1:
        return _input_shapes_parts(model.shapes, "")
    return [
        part
        for j, name in enumerate(names)
        for part in _input_shapes_parts(
            model.input_shapes(j), f" from {html.escape(name)}"
        )
    ]


def _input_shapes_parts(shapes, source: str) -> list[str]:
    """The shapes of one input (`source`: where they come from, or empty)."""
    if not len(shapes):
        return []
    return [
        f"<h2>Mode shapes{source}</h2><p>Each mode's shape over the outputs: every "
        "output's residue at the mode's pole, normalised to unit norm with "
        "the largest component real and positive (real parts shown; a "
        "lightly damped mode's shape is nearly real), with 95 % intervals "
        "from the covariance of every parameter (delta method). The norm "
        "adds the outputs in their own units: compare shapes over sensors "
        "of one quantity. The MAC (modal assurance criterion) of two modes "
        "is |phi_a<sup>H</sup> phi_b|<sup>2</sup> / (|phi_a|<sup>2</sup> "
        "|phi_b|<sup>2</sup>): near 1, these sensors cannot tell the two "
        "apart.</p>",
        table(*shapes_table(shapes), "html"),
        table(*mac_table(shapes.auto_mac), "html"),
    ]


def write_shared_report(staged: Path, model, v_est, v_val, **kwargs) -> None:
    """Write ``report.html`` and every figure's PNG into the folder `staged`.

    Parameters
    ----------
    staged : Path
        The (staging) folder.
    model : SharedDenominatorModel
    v_est, v_val : Validation
    **kwargs
        :func:`shared_report`'s keyword arguments (``headline`` first).
    """
    text, images = shared_report(model, v_est, v_val, **kwargs)
    for stem, data in images.items():
        (Path(staged) / f"{stem}.png").write_bytes(data)
    (Path(staged) / "report.html").write_text(text, encoding="utf-8")
