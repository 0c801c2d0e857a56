"""Everything that imports viser, in layers (pyproject.toml's ``viz-layers`` contract): the app's
:mod:`~rns_viz.viz.server` above its :mod:`~rns_viz.viz.panels` above the 3-D
:mod:`~rns_viz.viz.scene` above :mod:`~rns_viz.viz.clients` (who is connected, who operates).

The scene and its style are exported here for scripts that draw a model without the app."""

from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.style import SceneStyle, style_for

__all__ = ["FsmsScene", "SceneStyle", "style_for"]
