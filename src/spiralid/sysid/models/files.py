"""Reading a model file back: :func:`load_model`, for every kind of model.

A model file (``model.json``) names its kind in the field ``"model"``:
``"arx"`` (or absent, in files written before the field existed),
``"narx"`` or ``"shared-denominator"``; :data:`MODEL_KINDS` is the one table
from that name to the class whose ``from_dict`` reads it.
"""

from __future__ import annotations

from .identified import IdentifiedModel
from .narx import NARXModel
from .shared import SharedDenominatorModel

__all__ = ["MODEL_KINDS", "load_model"]

MODEL_KINDS = {
    "arx": IdentifiedModel,
    "narx": NARXModel,
    "shared-denominator": SharedDenominatorModel,
}


def model_kind(d: dict) -> str:
    """The kind a model file's dict names (``"arx"`` when it names none)."""
    kind = d.get("model", "arx")
    if kind not in MODEL_KINDS:
        raise ValueError(
            f"field 'model' must be one of {', '.join(MODEL_KINDS)}; got {kind!r}"
        )
    return kind


def load_model(d: dict):
    """The fitted model a ``to_dict()`` (a ``model.json``) describes.

    Parameters
    ----------
    d : dict
        The model file's content.

    Returns
    -------
    IdentifiedModel, NARXModel or SharedDenominatorModel
        As its field ``"model"`` says.

    Raises
    ------
    ValueError
        When `d` is not an object, names an unknown kind, or a field is
        missing or out of range (named in the message).
    """
    if not isinstance(d, dict):
        raise ValueError(f"a model must be a JSON object; got {type(d).__name__}")
    return MODEL_KINDS[model_kind(d)].from_dict(d)
