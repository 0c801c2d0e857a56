"""ū in words a student can read: beside the paper's path integral ∫ū dt (1/(kg·m)), the angle of
joint 2 along the path (deg) and how fast the joints turn at the chosen ū speed (deg/s), θ' = n ū (Eq. 27).
"""

from __future__ import annotations

import math

import numpy as np
import viser

from rns_viz.live.published.snapshot import Snapshot


class PathWords:
    """One line under the path slider, refreshed with the panel text (5 Hz)."""

    def __init__(self, server: viser.ViserServer, folder: viser.GuiFolderHandle, order: float) -> None:
        with folder:
            self.text = server.gui.add_markdown("", order=order)

    def refresh(self, snap: Snapshot) -> None:
        text = path_words(snap)
        if self.text.content != text:
            self.text.content = text


def path_words(snap: Snapshot) -> str:
    """'Where you are: θ = (90.0, 57.3)°; at ū = 30 joint 1 turns 1.2°/s, joint 2 5.6°/s' for a 1-D RNS, else ''
    (every joint of the path's arm: boom7's seven, TREP's two)."""
    n = snap.readouts.n
    if n is None or snap.sigma is None or not np.all(np.isfinite(snap.q)):
        return ""
    theta = ", ".join(f"{a:.1f}" for a in np.degrees(snap.q[-len(n) :]))
    u = snap.settings.ubar_speed  # 1/(kg m s)
    rates = ", ".join(f"joint {i + 1} {math.degrees(abs(v) * u):.0f}°/s" for i, v in enumerate(n))  # n: kg m
    return (
        f"Where you are: θ = **({theta})°** (the paper's ∫ū dt = {snap.sigma:.1f} 1/(kg·m)). "
        f"At ū = {u:g} 1/(kg·m·s) the joints turn here at {rates}."
    )
