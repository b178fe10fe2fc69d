"""Write a study's report: PNG figures, ``results.json``, ``report.html``.

The same three kinds of file as a reproduction (:mod:`spiralid.report.output`),
computed from a study's store by :func:`spiralid.study.analyse`; a rig record
with ``all_outputs`` adds its modes from every sensor, laid out as the
reproduction's (:func:`spiralid.report.shared_output.every_sensor_section`).
"""

from __future__ import annotations

import html
import json
from pathlib import Path

from spiralid.outputs.atomic import OutputFolder
from spiralid.report.html import figure, page, png, table
from spiralid.report.output import versions
from spiralid.report.shared_output import every_sensor_lines, every_sensor_section
from spiralid.study import StudyResults
from spiralid.study.spec import BASELINES

__all__ = [
    "STUDY_FILES",
    "partial_note",
    "study_results_dict",
    "study_summary",
    "write_study_report",
]

STUDY_FILES = (
    "results.json",
    "report.html",
    "study_convergence.png",
    "study_claim_a12.png",
    "study_anytime.png",
)

_CLAIM_HEAD = [
    "record",
    "predictor",
    "parametrisation",
    "n",
    "median {a}",
    "median {b}",
    *BASELINES.values(),
    "p",
    "p (Holm)",
    "A12",
    "verdict",
]
_CELL_HEAD = ["configuration", "n", "median", "IQR", "best", "worst", "fit %", "s"]


def _g(x) -> str:
    return "-" if x is None else f"{x:.4g}"


def _baseline_cost(res: StudyResults, data: str, predictor: str, label: str):
    row = res.baselines.get((data, predictor), {}).get(label)
    return None if row is None else row["cost"]


def _claim_rows(res: StudyResults) -> list[list]:
    a, b = res.claim
    return [
        [
            c["data"],
            c["predictor"],
            c["parametrization"],
            "/".join(map(str, c["n"])),
            _g(c[f"median {a}"]),
            _g(c[f"median {b}"]),
            *(
                _g(_baseline_cost(res, c["data"], c["predictor"], label))
                for label in BASELINES.values()
            ),
            f"{c['p_two_sided']:.3g}",
            f"{c['p_holm']:.3g}",
            f"{c['a12']:.2f}",
            c["verdict"],
        ]
        for c in res.claims
    ]


def _claim_head(res: StudyResults) -> list[str]:
    a, b = res.claim
    return [h.format(a=a, b=b) for h in _CLAIM_HEAD]


def _cell_rows(res: StudyResults, reading) -> list[list]:
    rows = []
    for label in res.labels:
        if (reading, label) not in res.cells:
            continue
        s = res.statistics(reading, label)
        rows.append(
            [
                label,
                s["n"],
                _g(s["cost_median"]),
                f"[{s['cost_q1']:.4g}, {s['cost_q3']:.4g}]",
                _g(s["cost_best"]),
                _g(s["cost_worst"]),
                f"{s['fit_val_median']:.1f}",
                f"{s['seconds_median']:.2f}",
            ]
        )
    for label, row in res.baselines.get(reading[:2], {}).items():
        rows.append(
            [
                label,
                1,
                _g(row["cost"]),
                "-",
                "-",
                "-",
                f"{row['fit_val']:.1f}",
                f"{row['seconds']:.2f}",
            ]
        )
    return rows


_ANYTIME_HEAD = ["record", "predictor", "parametrization", "budget"]


def _anytime_head(res: StudyResults) -> list[str]:
    a, b = res.claim
    return [*_ANYTIME_HEAD, a, b, "p", "p (Holm)", "A12", "verdict"]


def _anytime_rows(res: StudyResults) -> list[list]:
    return [
        [
            *r["reading"],
            f"{r['budget']:,}",
            _g(r["median_x"]),
            _g(r["median_y"]),
            _g(r["p_two_sided"]),
            _g(r["p_holm"]),
            f"{r['a12']:.2f}",
            r["verdict"],
        ]
        for r in res.anytime.get("rows", [])
    ]


def _crossover_lines(res: StudyResults) -> list[str]:
    """One sentence per reading whose verdict changes with the budget."""
    out = []
    for rd, budgets in res.anytime.get("crossovers", {}).items():
        if not budgets:
            continue
        rows = {
            r["budget"]: r["verdict"] for r in res.anytime["rows"] if r["reading"] == rd
        }
        ladder = sorted(rows)
        steps = []
        for b in budgets:
            before = ladder[ladder.index(b) - 1]
            steps.append(f"{rows[before]} at {before:,} -> {rows[b]} at {b:,}")
        out.append(f"{', '.join(map(str, rd))}: " + "; ".join(steps))
    return out


def anytime_summary(res: StudyResults) -> str:
    """The claim at every budget of the ladder, as text."""
    if not res.anytime.get("rows"):
        return ""
    a, b = res.claim
    lines = [
        f"The claim at every budget ({a} against {b}, best cost after that many "
        f"evaluations, from the stored histories; Holm over all "
        f"{res.anytime['family']} tests: readings x budgets)",
        "",
        table(_anytime_head(res), _anytime_rows(res)),
        "",
    ]
    flips = _crossover_lines(res)
    lines.append(
        "Where the verdict changes with the budget: " + " | ".join(flips)
        if flips
        else "The verdict of every reading is the same at every budget."
    )
    return "\n".join(lines)


def partial_note(res: StudyResults) -> str:
    """What a report of a partly run study covers; empty when no run and
    no fit from every sensor is missing."""
    missing = []
    if res.missing_runs:
        missing.append(
            f"the store holds {res.stored_runs} of the study's {res.expected_runs} "
            f"runs ({res.missing_runs} missing: the study stopped early or runs "
            "failed)"
        )
    if res.missing_modes:
        missing.append(
            "it holds no modes from every sensor of "
            f"{', '.join(map(repr, res.missing_modes))} (the study stopped before "
            "that fit)"
        )
    if not missing:
        return ""
    return (
        f"{'; '.join(missing)}; this report covers what the store holds only; "
        "rerun the study to compute the rest"
    )


def _verdict_count(res: StudyResults) -> str:
    a, b = res.claim
    if not res.claims:
        return f"No reading has runs of both {a} and {b} yet: nothing to test."
    wins = [c for c in res.claims if c["verdict"] == f"{a} better"]
    return (
        f"{a} is significantly better than {b} on {len(wins)} of "
        f"{len(res.claims)} readings."
    )


def study_summary(res: StudyResults) -> str:
    """The "where the claim holds" table as text."""
    a, b = res.claim
    note = partial_note(res)
    lines = [f"Partial study: {note}.", ""] if note else []
    lines += [
        f"Where the claim holds: {a} against {b}, estimation cost over seeds "
        f"(rank-sum test, Holm-adjusted over {len(res.claims)} readings, "
        f"alpha = {res.alpha:g}; A12 > 0.5 favours {a})",
        "",
        table(_claim_head(res), _claim_rows(res)),
        "",
        _verdict_count(res),
    ]
    anytime = anytime_summary(res)
    if anytime:
        lines += ["", anytime]
    for record, fit in res.modes.items():
        lines += ["", *every_sensor_lines(fit, f"Modes from every sensor: {record}")]
    return "\n".join(lines)


# What the single-output models beside a record's shared fit are.
_MODELS = (
    "the single-output models identified on the record's one sensor (the best "
    "run of each configuration on each reading) and the baselines of each "
    "predictor"
)


def _every_sensor_sections(res: StudyResults) -> list[str]:
    """Each rig record's modes from every sensor (``all_outputs``)."""
    return [
        every_sensor_section(
            fit,
            res.modes_comparison(record),
            _MODELS,
            title=f"Modes from every sensor: {record}",
        )
        for record, fit in res.modes.items()
    ]


def study_results_dict(res: StudyResults, spec_text: str, command=None) -> dict:
    """Everything the report shows, as JSON-ready data."""
    return {
        "command": command,
        "versions": versions(),
        "specification": spec_text,
        "claim": list(res.claim),
        "alpha": res.alpha,
        "runs": {"stored": res.stored_runs, "expected": res.expected_runs},
        "claims": res.claims,
        "anytime": {
            "budgets": res.anytime.get("budgets", []),
            "holm_family": res.anytime.get("family", 0),
            "rows": [
                {
                    **{k: v for k, v in r.items() if k != "reading"},
                    "data": r["reading"][0],
                    "predictor": r["reading"][1],
                    "parametrization": r["reading"][2],
                }
                for r in res.anytime.get("rows", [])
            ],
            "crossovers": [
                {
                    "data": rd[0],
                    "predictor": rd[1],
                    "parametrization": rd[2],
                    "budgets": budgets,
                }
                for rd, budgets in res.anytime.get("crossovers", {}).items()
            ],
        },
        "cells": [
            {
                "data": rd[0],
                "predictor": rd[1],
                "parametrization": rd[2],
                "label": label,
                **res.statistics(rd, label),
                "seeds": res.cells[rd, label]["seeds"].tolist(),
                "cost": res.cells[rd, label]["cost"].tolist(),
                "fit_val": res.cells[rd, label]["fit_val"].tolist(),
            }
            for rd in res.readings
            for label in res.labels
            if (rd, label) in res.cells
        ],
        "baselines": [
            {
                "data": d,
                "predictor": p,
                "label": label,
                "cost": row["cost"],
                "fit_val": row["fit_val"],
            }
            for (d, p), rows in res.baselines.items()
            for label, row in rows.items()
        ],
        # Only for rig records with all_outputs, so that a study without
        # them writes the single-output keys alone.
        **(
            {
                "modes_from_every_sensor": {
                    record: {
                        **fit.to_dict(),
                        "comparison": res.modes_comparison(record),
                    }
                    for record, fit in res.modes.items()
                }
            }
            if res.modes
            else {}
        ),
    }


def _html(res: StudyResults, images: dict, spec_text: str, command) -> str:
    e = html.escape
    a, b = res.claim
    parts = [
        f"<h1>Where does the paper's claim hold? {e(a)} against {e(b)}</h1>",
        f"<p>Command: <code>{e(command or 'spiralid study')}</code></p>",
        "<p>Each reading of the paper's cost (record, predictor, "
        "parametrisation) ran every configuration over the seeds at one "
        "budget. Costs are eq. (2)-(3) on the estimation part at the default "
        "gain (100 = the zero model). The rank-sum test compares the two "
        "configurations' costs per reading; the p-values are Holm-adjusted over "
        "all readings; A12 is the probability that a run of "
        f"{e(a)} ends below a run of {e(b)}.</p>",
    ]
    note = partial_note(res)
    if note:
        parts.append(f"<p><strong>Partial study:</strong> {e(note)}.</p>")
    parts += [
        "<h2>Where the claim holds</h2>",
        table(_claim_head(res), _claim_rows(res), "html"),
        f"<p>{e(_verdict_count(res))}</p>",
    ]
    if res.anytime.get("rows"):
        flips = _crossover_lines(res)
        parts += [
            "<h2>The claim at every budget</h2>",
            "<p>The best cost of every run after that many evaluations, read "
            "from its stored history (no run repeated); p-values Holm-adjusted "
            f"over all {res.anytime['family']} tests (readings x budgets).</p>",
            table(_anytime_head(res), _anytime_rows(res), "html"),
            "<p>"
            + (
                "Where the verdict changes: " + e(" | ".join(flips))
                if flips
                else "The verdict of every reading is the same at every budget."
            )
            + "</p>",
        ]
    for stem, data in images.items():
        parts.append(figure(stem, data))
    parts += _every_sensor_sections(res)
    parts.append("<h2>Every reading</h2>")
    for rd in res.readings:
        parts.append(f"<h3>{e(', '.join(map(str, rd)))}</h3>")
        parts.append(table(_CELL_HEAD, _cell_rows(res, rd), "html"))
    parts.append(f"<h2>Specification</h2><pre>{e(spec_text)}</pre>")
    return page("spiralid study: where does the paper's claim hold?", parts)


def write_study_report(
    res: StudyResults,
    out: str | Path,
    *,
    spec_text: str = "",
    force: bool = False,
    command: str | None = None,
) -> list[Path]:
    """Write figures (PNG), ``results.json`` and ``report.html`` into `out`.

    Returns the paths written. Refuses a non-empty directory unless `force`
    (the command line passes `force` once it has checked that the folder
    holds only the study's own files).
    """
    from spiralid.report.study_figures import study_figures

    with OutputFolder(out, force) as folder:
        images = {}
        for stem, fig in study_figures(res).items():
            images[stem] = png(fig)
            (folder.path / f"{stem}.png").write_bytes(images[stem])
        (folder.path / "results.json").write_text(
            json.dumps(study_results_dict(res, spec_text, command), indent=2)
        )
        (folder.path / "report.html").write_text(
            _html(res, images, spec_text, command), encoding="utf-8"
        )
        return folder.commit(last="report.html")
