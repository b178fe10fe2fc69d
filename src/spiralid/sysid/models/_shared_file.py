"""``SharedDenominatorModel``'s ``model.json``: the dictionary it writes and
the checked constructor fields it reads back (private)."""

from __future__ import annotations

import numpy as np

from . import _fields
from .arx import ARX

# Provenance fields this file writes as null for NaN.
_NULLABLE = ("cost", "gain")


def model_dict(model, timings: bool) -> dict:
    """What :meth:`SharedDenominatorModel.to_dict` returns."""
    out = {
        "model": "shared-denominator",
        "structure": {"na": model.arx.na, "nb": model.arx.nb, "nk": model.arx.nk},
        "ts": model.ts,
        "method": model.method,
        "a": model.a.tolist(),
        "b": model.b.tolist(),
        "input_name": model.input_name,
        "input_unit": model.input_unit,
        "output_names": list(model.output_names),
        "output_units": list(model.output_units),
        "u_offset": model.u_offset,
        "y_offsets": list(model.y_offsets),
        "cost": _fields.plain(model.cost),
        "costs": None
        if model.costs is None
        else [_fields.plain(c) for c in model.costs],
        "weights": None if model.weights is None else model.weights.tolist(),
        "covariance": None if model.covariance is None else model.covariance.tolist(),
        "shape_factor": (
            None if model.shape_factor is None else model.shape_factor.tolist()
        ),
        "integrators": list(model.integrators),
        "modes": model.modes.to_dict(),
    }
    # The provenance every fitted model writes, after the keys this
    # file had before it shared them (NaN as null, as for the cost).
    if model.n_inputs > 1:
        out["input_names"] = list(model.input_names)
        out["input_units"] = list(model.input_units)
        out["u_offsets"] = list(model.u_offsets)
    prov = model._provenance_dict()
    prov["gain"] = _fields.plain(model.gain)
    if not timings:
        del prov["timings"]
    out.update({k: v for k, v in prov.items() if k not in out})
    return out


def model_fields(d, provenance_fields) -> dict:
    """The constructor's keyword arguments from a ``model.json`` object `d`,
    each field checked where it is read; `provenance_fields` is the model
    class's reader of the fields every fitted model shares."""
    if not isinstance(d, dict):
        raise ValueError(f"a model must be a JSON object; got {type(d).__name__}")
    kind = d.get("model")
    if kind != "shared-denominator":
        raise ValueError(f"field 'model' must be 'shared-denominator'; got {kind!r}")
    s = d.get("structure")
    if not isinstance(s, dict):
        raise ValueError(f"field 'structure' must be an object; got {s!r:.60}")
    na, nb, nk = (
        _fields.integer(s, key, f"an integer >= {low}", low.__le__, where="structure.")
        for key, low in (("na", 1), ("nb", 1), ("nk", 0))
    )
    names = _fields.texts(d, "output_names")
    p = len(names)
    if not p:
        raise ValueError("field 'output_names' must name at least one output")

    def optional(key, shape, null=None):
        if d.get(key) is None:
            return None
        return _fields.numbers(d, key, shape, null=null)

    # Files written before the provenance was shared hold only its
    # method, cost, input name, unit and offset: the rest defaults. A
    # null cost or gain is NaN; any method name is read (the file
    # names what estimated it, nothing here depends on it).
    known = {k: v for k, v in d.items() if v is not None or k not in _NULLABLE}
    provenance = provenance_fields({"method": "", **known}, None, penalty=0.0)
    inputs = _fields.texts(d, "input_names", None, [])
    m = max(len(inputs), 1)
    several = {}
    if m > 1:
        several = dict(
            input_names=tuple(inputs),
            input_units=tuple(_fields.texts(d, "input_units", m, [""] * m)),
            u_offsets=tuple(_fields.numbers(d, "u_offsets", (m,), [0.0] * m)),
        )
    integrators = _fields.numbers(d, "integrators", (p,), [0] * p)
    if not np.all(integrators == np.round(integrators)):
        raise ValueError(
            "field 'integrators' must be whole counts, one per output; got "
            f"{d['integrators']!r:.60}"
        )
    # The factor of every parameter's covariance: a, then each output's
    # numerators from each input.
    n_params = na + p * m * nb
    return dict(
        a=_fields.numbers(d, "a", (na,)),
        b=_fields.numbers(d, "b", (p, m * nb)),
        arx=ARX(na, nb, nk),
        ts=_fields.number(d, "ts", "a number > 0", _fields.positive),
        output_names=names,
        output_units=_fields.texts(d, "output_units", p, [""] * p),
        y_offsets=tuple(_fields.numbers(d, "y_offsets", (p,), [0.0] * p)),
        costs=optional("costs", (p,), null=np.nan),
        weights=optional("weights", (p,)),
        # JSON has no infinity: an infinite variance is written as null.
        covariance=optional("covariance", (na, na), null=np.inf),
        shape_factor=optional("shape_factor", (n_params, n_params)),
        integrators=tuple(int(k) for k in integrators),
        **provenance,
        **several,
    )
