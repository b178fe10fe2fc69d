"""Reading a model file back: :func:`load_model`, for every kind of model.

A model file (``model.json``) names its kind in the field ``"model"``:
``"arx"`` (or absent, in files written before the field existed),
``"narx"``, ``"shared-denominator"``, ``"greybox"`` or
``"neural-state-space"``; :data:`MODEL_KINDS`
is the one table from that name to the class whose ``from_dict`` reads it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from .greybox_model import GreyBoxModel
from .identified import IdentifiedModel
from .narx import NARXModel
from .neural_state_space_model import NeuralStateSpaceModel
from .protocol import FittedModelProtocol
from .shared import SharedDenominatorModel

__all__ = ["MODEL_KINDS", "load_model"]

MODEL_KINDS = {
    "arx": IdentifiedModel,
    "narx": NARXModel,
    "shared-denominator": SharedDenominatorModel,
    "greybox": GreyBoxModel,
    "neural-state-space": NeuralStateSpaceModel,
}


def model_kind(d: dict) -> str:
    """The kind a model file's dict names (``"arx"`` when it names none)."""
    kind = d.get("model", "arx")
    if kind not in MODEL_KINDS:
        raise ValueError(
            f"field 'model' must be one of {', '.join(MODEL_KINDS)}; got {kind!r}"
        )
    return kind


def load_model(d: dict | str | os.PathLike) -> FittedModelProtocol:
    """The fitted model a ``to_dict()`` (a ``model.json``) describes.

    Parameters
    ----------
    d : dict, str or path-like
        The model file's content, or the path of the file (UTF-8 JSON).

    Returns
    -------
    FittedModelProtocol
        The kind its field ``"model"`` names: IdentifiedModel, NARXModel,
        SharedDenominatorModel, GreyBoxModel or NeuralStateSpaceModel.

    Raises
    ------
    ValueError
        When the content is not an object, names an unknown kind, or a
        field is missing or out of range (named in the message); when the
        file is not JSON.
    OSError
        When the file cannot be read.
    """
    if isinstance(d, str | os.PathLike):
        path = Path(d)
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
        except ValueError as exc:
            raise ValueError(
                f"`d` {str(path)!r} is not a JSON model file: {exc}"
            ) from None
    if not isinstance(d, dict):
        raise ValueError(f"a model must be a JSON object; got {type(d).__name__}")
    return MODEL_KINDS[model_kind(d)].from_dict(d)
