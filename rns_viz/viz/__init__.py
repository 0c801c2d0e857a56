"""Everything that imports viser: the FSMS scene (robot, elastic base, overlays) and its style."""

from rns_viz.viz.scene import FsmsScene
from rns_viz.viz.style import SceneStyle, style_for

__all__ = ["FsmsScene", "SceneStyle", "style_for"]
