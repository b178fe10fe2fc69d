"""Selection of the default NARX's training length on the paper experiment.

The default NARX (``identify(est, NARX(8, 8, 0))``, method ``"spiral"``)
runs an Eb-SDA search over the weights and then a final
Levenberg-Marquardt polish with early stopping from the search's centre and
the linear start. This script runs the search once per seed and then the
final polish (``narx._train``) under several training settings, so the
settings are compared on the same search; it prints the validation fit of
each next to the default ARX's and the goal of ``nonparametric.py --goals``
(the ARX fit plus min(5, half the remaining misfit) on the nonlinear rig,
within 0.5 points on the linear one).

The default setting (identify's own run) is printed first. Settings are
``name=key:value,key:value`` with the keys ``max_rounds``,
``patience``, ``patience_share`` (:meth:`NARXProblem.polish`) and
``n_inits`` (the linear start with this many Glorot draws of the hidden
weights, drawn after the search).

With ``--refit`` each seed also gets the row ``refit=none``: the same
run's early-stopped network as trained on the training part, without the
replay on the whole record (``identify(..., refit="none")``, contained by
the linear start as identify contains it), from the same search and
polish, so it costs no second fit.

Usage: ``python benchmarks/narx_stopping.py --seeds 4-7 [--record "nonlinear
acc"] [--settings "default=max_rounds:50 long=max_rounds:500"] [--refit]``
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import os
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

from _cli import seed_list

from spiralid.fms import nonlinear_rig, paper_experiment
from spiralid.sysid import ARX, NARX, fit_percent, identify
from spiralid.sysid.estimation.narx import problem as narx_problem
from spiralid.sysid.estimation.narx import starts as narx_starts
from spiralid.sysid.estimation.narx import training as narx_mod

RECORDS = {
    "nonlinear acc": (True, "end_acceleration", 0),
    "nonlinear hub": (True, "hub_angle", 2),
    "linear acc": (False, "end_acceleration", 0),
    "linear hub": (False, "hub_angle", 2),
}


def parse_settings(text: str) -> dict[str, dict]:
    out = {}
    for item in text.split():
        name, _, body = item.partition("=")
        opts = {}
        for kv in filter(None, body.split(",")):
            key, _, value = kv.partition(":")
            opts[key] = float(value) if key == "patience_share" else int(value)
        out[name] = opts
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=seed_list, default="4-7")
    ap.add_argument("--record", default="nonlinear acc", choices=list(RECORDS))
    ap.add_argument(
        "--settings",
        default="",
        help="space-separated name=key:value,... (see the module docstring)",
    )
    ap.add_argument(
        "--refit", action="store_true", help="add the refit=none row (same run)"
    )
    args = ap.parse_args()
    settings = parse_settings(args.settings)
    nonlinear, out, k = RECORDS[args.record]
    warnings.simplefilter("ignore")
    real_train = narx_mod._train
    real_stopped = narx_mod._early_stopped
    real_polish = narx_problem.NARXProblem.polish
    log: list = []
    captured: dict = {}

    def polish(self, p0, predictor, *a, **kw):
        t = time.perf_counter()
        p, rounds = real_polish(self, p0, predictor, *a, **kw)
        log.append((self.hold is not None, rounds, time.perf_counter() - t))
        return p, rounds

    narx_problem.NARXProblem.polish = polish
    print(f"## {args.record}, seeds {args.seeds}")
    print("| seed | setting | ARX fit % | NARX fit % | gain | target | met | start |")
    print("|---|---|---|---|---|---|---|---|")
    print("# columns after: best round, polish rounds per start, search s, train s")
    for seed in args.seeds:
        rig = nonlinear_rig() if nonlinear else None
        data = paper_experiment().run(rig=rig, rng=seed).iodata(out)
        est, val = data.split(2 / 3)
        arx = identify(est, ARX(8, 8, 0), integrator=k, rng=seed)
        fa = fit_percent(val.y, arx.simulate(data.u)[est.n :])
        target = fa + min(5.0, (100.0 - fa) / 2) if nonlinear else fa - 0.5
        captured.clear()

        def capture(problem, starts, linear, predictor, options, t0, **extra):
            captured.update(
                problem=problem,
                starts=dict(starts),
                linear=linear,
                predictor=predictor,
                rng=copy.deepcopy(problem.rng),
                refit=extra.get("refit"),
                nfev=problem.nfev,
                search_s=time.perf_counter() - t0,
            )
            log.clear()
            t = time.perf_counter()
            res = real_train(problem, starts, linear, predictor, options, t0, **extra)
            captured["train_s"] = time.perf_counter() - t
            captured["rounds"] = "/".join(str(r) for held, r, _ in log if held)
            return res

        def stopped(problem, starts, predictor, options):
            out = real_stopped(problem, starts, predictor, options)
            captured["stopped"] = out
            return out

        narx_mod._train = capture
        narx_mod._early_stopped = stopped
        st = NARX(7 if k else 8, 8, 0, integrator=k)
        try:
            model = identify(est, st, rng=seed)
        finally:
            narx_mod._train = real_train
            narx_mod._early_stopped = real_stopped
        fn = fit_percent(val.y, model.simulate(data.u)[est.n :])
        print(
            f"| {seed} | default | {fa:.2f} | {fn:.2f} | {fn - fa:+.2f} | "
            f"{target:.2f} | {'yes' if fn >= target else 'no'} | "
            f"{model.result.start} | {model.result.final_rounds} | "
            f"{captured['rounds']} | {captured['search_s']:.0f} | "
            f"{captured['train_s']:.0f} |",
            flush=True,
        )
        if args.refit:
            p, start, schedule = captured["stopped"]
            p, kept = narx_mod._contain(
                captured["problem"], p, captured["linear"], captured["predictor"]
            )
            m = dataclasses.replace(model, params=p)
            fn = fit_percent(val.y, m.simulate(data.u)[est.n :])
            print(
                f"| {seed} | refit=none | {fa:.2f} | {fn:.2f} | {fn - fa:+.2f} | "
                f"{target:.2f} | {'yes' if fn >= target else 'no'} | "
                f"{'linear' if kept else start} | "
                f"{sum(r for _, r in schedule)} |",
                flush=True,
            )
        for name, opts in settings.items():
            problem = captured["problem"]
            problem.rng = copy.deepcopy(captured["rng"])
            problem.nfev = captured["nfev"]
            starts = dict(captured["starts"])
            opts = dict(opts)
            n_inits = opts.pop("n_inits", 1)
            for i in range(2, n_inits + 1):
                starts[f"linear {i}"] = narx_starts._with_hidden(
                    problem, captured["linear"]
                )
            log.clear()
            t = time.perf_counter()
            res = real_train(
                problem,
                starts,
                captured["linear"],
                captured["predictor"],
                opts,
                t,
                refit=captured["refit"],
            )
            train_s = time.perf_counter() - t
            m = dataclasses.replace(model, params=res.x)
            fn = fit_percent(val.y, m.simulate(data.u)[est.n :])
            met = "yes" if fn >= target else "no"
            rounds = "/".join(str(r) for held, r, _ in log if held)
            print(
                f"| {seed} | {name} | {fa:.2f} | {fn:.2f} | {fn - fa:+.2f} | "
                f"{target:.2f} | {met} | {res.start} | {res.nit} | {rounds} | "
                f"{captured['search_s']:.0f} | {train_s:.0f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
