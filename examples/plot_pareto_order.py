"""
A Pareto front of models, and choosing an order
===============================================

:func:`spiralid.identify_pareto` searches stable ARX models against two
objectives at once: the simulation cost of the paper's eq. (2) and a
frequency-domain error (the coherence-weighted RMS of the model's gain
against the record's measured frequency response, in dB). Given several
orders, it searches each and merges them with the number of parameters as
a third objective. The front then offers three ways to pick a model, all
in :mod:`spiralid.sysid.validation.selection`: its knee, the lowest cost
under a bound on the frequency error (:func:`spiralid.choose`), and the
lowest order that validates within a point of the best
(:func:`spiralid.choose_order`).

This is the README's example ("Choosing a model from a Pareto front") on
the shipped DaISy robot arm: orders 2 to 8, 2,000 evaluations and 30 points
per order, one seed. That is a reduced budget (``identify_pareto``'s default
is 5,000 evaluations and 50 points per order); the numbers are this run's.
"""

import matplotlib.pyplot as plt

import spiralid as sid
from spiralid.report.pareto_figures import front_figure

# %%
# The front
# ---------
# Each order's search is seeded with the least-squares, Steiglitz-McBride
# and output-error estimates, and each objective's best point is polished
# locally (``seed_estimates=True`` and ``extremes_nfev=200``, the defaults);
# every model's ``result.start`` says where it came from.
est, val = sid.datasets.robot_arm().split(2 / 3)
front = sid.identify_pareto(est, range(2, 9), rng=0, max_nfev=2000, n_points=30)
print(len(front), "stable models; objectives", front.names)
print(f"{front.nfev} evaluations in {front.elapsed:.1f} s")

# %%
# Three choices
# -------------
# The knee is the point farthest from the plane through the front's
# extremes: a geometric property of the front, not a statement about
# validation. ``choose(front, max_frequency=4.0)`` is the lowest cost whose
# frequency-response error is at most 4 dB. ``choose_order`` validates each
# order's lowest-cost model on the held-out third and takes the lowest order
# within one point of the best; as it is chosen on that third, the fit it
# reports there is optimistic.
knee = front.knee_model
pick_index = sid.choose(front, max_frequency=4.0)
pick = front.models[pick_index]
by_fit = front.models[sid.choose_order(front, val, warmup=est)]
for name, model in (("knee", knee), ("<= 4 dB", pick), ("choose_order", by_fit)):
    fit = sid.validate(model, val, warmup=est).fit_percent
    objectives = ", ".join(f"{k} {v:.4g}" for k, v in model.result.objectives.items())
    print(f"{name:<13} {model.arx}  validation fit {fit:5.1f} %  ({objectives})")

# %%
# Least squares and output error at every order
# ---------------------------------------------
# The classical answers beside the front: at each order, the validation fit
# of the front's lowest-cost model (:func:`spiralid.sysid.fits_by_order`)
# against least squares and output error estimated on the same part.
by_order = sid.sysid.fits_by_order(front, val, warmup=est)
orders = list(range(2, 9))
fits = {"front, lowest cost": [], "LS": [], "OE": []}
print(f"{'order':<14} {'front':>7} {'LS':>7} {'OE':>7}")
for n in orders:
    arx = sid.ARX(n, n, 0)
    fits["front, lowest cost"].append(by_order[arx.na + arx.nb][1])
    for method in ("ls", "oe"):
        model = sid.identify(est, arx, method=method)
        fits[method.upper()].append(sid.validate(model, val, warmup=est).fit_percent)
    row = " ".join(f"{values[-1]:7.1f}" for values in fits.values())
    print(f"{arx!s:<14} {row}")

# %%
# Figures
# -------
# :func:`spiralid.report.pareto_figures.front_figure` draws the front in its
# first two objectives with the order as the colour, the knee as a star and
# the chosen point marked. It returns a ``Figure`` that pyplot does not
# track; ``plt.figure(fig)`` hands it to pyplot.
plt.figure(front_figure(front, chosen=pick_index))

# %%
# Validation fit against order, the front's models beside least squares and
# output error (plain matplotlib).
fig, ax = plt.subplots(figsize=(6, 3.5), layout="constrained")
for (label, values), marker in zip(fits.items(), "osd", strict=True):
    ax.plot(orders, values, marker=marker, label=label)
ax.set_xlabel("order n of ARX(n, n, 0)")
ax.set_ylabel("validation fit (%)")
ax.legend()
plt.show()
