"""The model dropdown: the bundled models the app serves and any parameter files given with ``--model``.

Each entry is a model key (:func:`rns_viz.params.model_key`); the label is what the dropdown shows.
A key with a selection suffix (``boom7#S=111000``) shows its model's label. A bundled model whose
optional extra is not installed (boom-panda without ``rns-viz[panda]``) is listed with the install
command in its label; choosing it is refused with the same hint, and the app keeps its model.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from rns_viz.params import BUNDLED_MODELS, MODEL_NAMES, missing_extra, model_key, model_source

MODEL_LABELS = {
    "trep": "TREP (2R on a flexible beam)",
    "planar3r": "planar 3R on a spring",
    "boom7": "7-DOF arm on a flexible boom (3-D)",
    "trep2": "TREP with a compensating arm",
    "boom-panda": "Franka Panda on a flexible boom (3-D)",
}


def install_hint(extra: str) -> str:
    """What a label adds for a model whose optional extra is not installed."""
    return f" (not installed: pip install 'rns-viz[{extra}]')"


def label_of(key: str) -> str:
    """The dropdown label of a model key: a bundled model's description, or a file's name."""
    source = model_source(key)
    if source in BUNDLED_MODELS:
        extra = missing_extra(source)
        return MODEL_LABELS.get(source, source) + ("" if extra is None else install_hint(extra))
    return f"file: {Path(source).name}"


class ModelMenu:
    """Labels and keys of the models a client may choose; ``key_of`` refuses a label not offered."""

    def __init__(self, extra: Iterable[str] = ()) -> None:
        keys = list(MODEL_NAMES) + [model_key(model_source(k)) for k in extra]
        self.keys: dict[str, str] = {}  # label -> key, in menu order
        for key in dict.fromkeys(keys):
            label = label_of(key)
            if label in self.keys:  # two files of one name: the full path tells them apart
                label = f"file: {model_source(key)}"
            self.keys[label] = key
        self._labels = {key: label for label, key in self.keys.items()}

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(self.keys)

    def label(self, key: str) -> str:
        """The label of a model key (its selection ignored)."""
        return self._labels.get(model_key(model_source(key)), label_of(key))

    def key_of(self, label: str) -> str:
        if label not in self.keys:
            raise ValueError(f"unknown model {label!r}; choose one of the menu's models")
        return self.keys[label]
