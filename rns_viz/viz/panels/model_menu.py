"""The model dropdown: the bundled models the app serves and any parameter files given with ``--model``.

Each entry is a model key (:func:`rns_viz.params.model_key`); the label is what the dropdown shows, the
``[app] label`` of the model's parameter file (a file without one: ``file: NAME.toml``). A key with a
selection suffix (``boom7#S=111000``) shows its model's label. A model whose optional extra is not
installed (boom-panda without ``rns-viz[panda]``) is listed with the install command in its label;
choosing it is refused with the same hint, and the app keeps its model.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import cache
from pathlib import Path

from rns_viz.params import MODEL_NAMES, missing_extra, model_key, model_source, param_file_for


def install_hint(extra: str) -> str:
    """What a label adds for a model whose optional extra is not installed."""
    return f" (not installed: pip install 'rns-viz[{extra}]')"


def label_of(key: str) -> str:
    """The dropdown label of a model key: its parameter file's ``[app] label``, or the file's name. Read once
    per model (the menu reads every model's when the app starts), so a file gone bad later keeps its label."""
    return _label(model_source(key))


@cache
def _label(source: str) -> str:
    label = param_file_for(source).app.label or f"file: {Path(source).name}"
    extra = missing_extra(source)
    return label + ("" if extra is None else install_hint(extra))


class ModelMenu:
    """Labels and keys of the models a client may choose; ``key_of`` refuses a label not offered. Reads
    every model's parameter file (ModelFileError for a bad one: the app refuses it at start)."""

    def __init__(self, extra: Iterable[str] = ()) -> None:
        keys = list(MODEL_NAMES) + [model_key(model_source(k)) for k in extra]
        self.keys: dict[str, str] = {}  # label -> key, in menu order
        self._headings: dict[str, str] = {}  # key -> the heading of its presets' row
        for key in dict.fromkeys(keys):
            label = label_of(key)
            if label in self.keys:  # two files of one label: the full path tells them apart
                label = f"file: {model_source(key)}"
            self.keys[label] = key
            self._headings[key] = param_file_for(key).app.presets_heading or label
        self._labels = {key: label for label, key in self.keys.items()}

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(self.keys)

    def source_key(self, key: str) -> str:
        """The menu's key of a model key (its selection dropped)."""
        return model_key(model_source(key))

    def label(self, key: str) -> str:
        """The label of a model key (its selection ignored)."""
        return self._labels.get(self.source_key(key), label_of(key))

    def presets_heading(self, key: str) -> str:
        """The heading of a model's row of presets (``[app] presets_heading``, else its label)."""
        return self._headings[self.source_key(key)]

    def key_of(self, label: str) -> str:
        if label not in self.keys:
            raise ValueError(f"unknown model {label!r}; choose one of the menu's models")
        return self.keys[label]
