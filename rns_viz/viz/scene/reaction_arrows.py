"""The arm's reaction on a 6-DOF base, all six rows of −(H_bm θ'' + c_b) (Eq. 1), drawn at the boom's tip
in the base (tip) frame: a force arrow (N) and a moment arrow (N m, along the moment's axis, right-hand
rule), each scaled by the scene's force scale (m of arrow per N, or per N m), stated in its label.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import viser

from rns_viz.viz.scene.style import SceneStyle

MOMENT_COLOUR = (200, 0, 140)  # magenta: apart from the force's red and the coupling momentum's purple


class WrenchArrows:
    """Force and moment arrows under the base node; hidden while the reaction is too small to draw."""

    FORCE = "/base/reaction_force"
    MOMENT = "/base/reaction_moment"

    def __init__(self, server: viser.ViserServer, style: SceneStyle, colour: tuple[int, int, int]) -> None:
        self.server, self.style = server, style
        r = style.marker_radius
        arrow = dict(shaft_radius=0.25 * r, head_radius=0.6 * r, head_length=1.5 * r, visible=False)
        scene = server.scene
        self.arrows = (
            scene.add_arrows(self.FORCE, np.zeros((1, 2, 3)), colour, **arrow),  # type: ignore[arg-type]
            scene.add_arrows(self.MOMENT, np.zeros((1, 2, 3)), MOMENT_COLOUR, **arrow),  # type: ignore[arg-type]
        )
        self.labels = (
            scene.add_label(self.FORCE + "/label", "", anchor="top-center", visible=False),
            scene.add_label(self.MOMENT + "/label", "", anchor="top-center", visible=False),
        )
        self._shown: tuple[tuple[float, ...], str, bool] | None = None

    def set(self, wrench: Sequence[float], label: str, show: bool) -> None:
        """``wrench`` = (f_x, f_y, f_z in N; m_x, m_y, m_z in N m) in the base frame."""
        key = (tuple(float(w) for w in wrench), label, show)
        if key == self._shown:
            return
        self._shown = key
        w = np.nan_to_num(np.asarray(wrench, dtype=float))
        st = self.style
        with self.server.atomic():
            for part, (arrow, text, unit) in enumerate(zip(self.arrows, self.labels, ("N", "N m"), strict=True)):
                vec = w[3 * part : 3 * part + 3] if len(w) == 6 else np.zeros(3)
                size = float(np.linalg.norm(vec))
                length = min(size * st.force_scale, st.force_arrow_max)
                visible = show and length > 0.5 * 1.5 * st.marker_radius
                arrow.visible = text.visible = visible
                if visible:
                    tip = length * vec / size
                    arrow.points = np.stack([np.zeros(3), tip])[None]
                    text.position = tip
                    name = "force" if part == 0 else "moment"
                    text.text = (
                        f"{label}, {name} |{'F' if part == 0 else 'M'}| = {size:.3g} {unit} "
                        f"(({', '.join(f'{v:+.2g}' for v in vec)}) {unit}; {st.force_scale:.2g} m per {unit})"
                    )
