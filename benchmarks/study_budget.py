"""Does Eb-SDA overtake SDA given a larger budget? (the paper's Figure 6a story)

The paper reports SDA leading early and Eb-SDA overtaking it later, after
tens of minutes. This study runs the reproduction's paper-faithful and
reflection arms at growing budgets of cost evaluations on the default
simulated rig and prints, per budget, the median, best and worst estimation
cost over seeds, the median validation fit and the one-sided rank-sum p-value
of "Eb-SDA lower than SDA". Paper constants untouched.

Run: ``python benchmarks/study_budget.py [n_seeds] [budget ...]``
(default 10 seeds, budgets 5000 20000 100000).
"""

import sys
import time

from spiralid.reproduction import Configuration, default_data, reproduce

CONFIGS = (
    Configuration("SDA", "sda"),
    Configuration("Eb-SDA", "ebsda"),
    Configuration("SDA (reflection)", "sda", "reflection"),
    Configuration("Eb-SDA (reflection)", "ebsda", "reflection"),
)


def main() -> None:
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    budgets = [int(b) for b in sys.argv[2:]] or [5_000, 20_000, 100_000]
    data = default_data()
    print(f"default rig, ARX(8, 8, 0), simulation cost, {n_seeds} seeds, 50 points")
    print(
        f"{'budget':>8} {'method':<20} {'median':>8} {'best':>8} {'worst':>8} "
        f"{'val fit':>8} {'p(Eb<SDA)':>10} {'wall s':>7}"
    )
    for budget in budgets:
        t0 = time.perf_counter()
        rep = reproduce(data, seeds=n_seeds, max_nfev=budget, configurations=CONFIGS)
        wall = time.perf_counter() - t0
        p = {
            "": rep.ranksum("Eb-SDA", "SDA")["p_less"],
            " (reflection)": rep.ranksum("Eb-SDA (reflection)", "SDA (reflection)")[
                "p_less"
            ],
        }
        for c in CONFIGS:
            s = rep.statistics(c.label)
            tag = c.label.removeprefix("Eb-SDA").removeprefix("SDA")
            pv = f"{p[tag]:10.3g}" if c.method == "ebsda" else " " * 10
            print(
                f"{budget:>8} {c.label:<20} {s['cost_median']:8.2f} "
                f"{s['cost_best']:8.2f} {s['cost_worst']:8.2f} "
                f"{s['fit_val_median']:8.1f} {pv} {wall:7.1f}"
            )
    ls, oe = rep.baselines["LS"], rep.baselines["OE"]
    print(
        f"baselines: LS cost {ls.cost:.2f} (fit {ls.fit_val:.1f} %), "
        f"OE cost {oe.cost:.2f} (fit {oe.fit_val:.1f} %)"
    )


if __name__ == "__main__":
    main()
