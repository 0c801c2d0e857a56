"""The factor the render thread draws the base deflection with, each frame: the auto scale's
(rns_viz.viz.scene.auto_scale; shown in the panel's box too) while *Auto deflection scale* is ticked,
else the operator's fixed factor from *Base deflection drawn ×*."""

from __future__ import annotations

from rns_viz.defaults import defaults_for
from rns_viz.live.published.snapshot import Snapshot
from rns_viz.model import FsmsModel
from rns_viz.viz.panels.control_panel import GuiElements
from rns_viz.viz.panels.inputs import Controls
from rns_viz.viz.scene.auto_scale import AutoExaggeration
from rns_viz.viz.scene.view_toggles import ViewToggles


class DrawnFactor:
    """One model's drawn factor; built with the model's scene."""

    def __init__(self, model: FsmsModel, gui: GuiElements, controls: Controls, view: ViewToggles) -> None:
        self.m, self.gui, self.controls, self.view = model.m, gui, controls, view
        self.auto = AutoExaggeration(model.arm_reach, model.base_rotational, defaults_for(model).exaggeration)

    def for_frame(self, snap: Snapshot) -> float:
        """The factor for this frame's drawing (the ghost's base counts while the ghost is drawn)."""
        g, controls = self.gui, self.controls
        if not controls.good(g.auto_exaggeration):
            return float(controls.good(g.exaggeration))
        shadow = None if snap.q_shadow is None or not self.view.on("ghost") else snap.q_shadow[: self.m]
        factor = self.auto.observe(snap.t, (snap.q[: self.m], shadow))
        if factor != controls.good(g.exaggeration) and not g.exaggeration.typing():
            controls.show(g.exaggeration, factor)
        return factor
