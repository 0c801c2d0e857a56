"""Text of the panel's status line and readouts (HTML), from a session snapshot. Pure functions."""

from __future__ import annotations

import html
import math

import numpy as np

from rns_viz.live.published.snapshot import Snapshot
from rns_viz.params import key_selection
from rns_viz.viz.panels.model_menu import label_of
from rns_viz.viz.panels.units import si
from rns_viz.viz.scene.quantities import BASE_VIBRATION, HAND_MISS, MOMENTUM, REACTION

OK_COLOUR = "#1b7f3b"
WARN_COLOUR = "#c77700"
BAD_COLOUR = "#c0262d"


def _badge(text: str, colour: str, why: str = "") -> str:
    """A coloured word; ``why``: what it means, shown on hovering it."""
    title = f' title="{html.escape(why)}"' if why else ""
    return (
        f'<span style="background:{colour};color:white;border-radius:4px;padding:1px 6px;'
        f'font-weight:600;font-size:0.8em"{title}>{text}</span>'
    )


BEHIND_WHY = "This machine cannot simulate at the chosen speed: the factor beside says how fast it runs."
SKIPPED_WHY = (
    "The processor was busy elsewhere for longer than a quarter of a second: the simulation gave up that much "
    "simulated time rather than run fast to catch up. The plots show the simulation's own time."
)


def status_html(snap: Snapshot) -> str:
    """One line: model, simulated time, real-time factor and state, with flags in colour."""
    st = snap.settings
    model = html.escape(label_of(st.model))
    if snap.diverged:
        state = _badge("STOPPED", BAD_COLOUR)
    elif snap.paused:
        state = _badge("PAUSED", WARN_COLOUR)
    else:
        state = _badge("RUNNING", OK_COLOUR)
    rtf = "–" if snap.paused or not math.isfinite(snap.rtf) else f"{snap.rtf:.2f}"
    behind = ""  # the rate beside it says by how much; a skip after a stall is said apart (the rate may be back)
    if snap.behind:
        behind = " " + _badge("FALLING BEHIND", BAD_COLOUR, BEHIND_WHY)
    elif snap.skipped > 0.0:
        behind = " " + _badge(f"SKIPPED {snap.skipped:.2f} s", WARN_COLOUR, SKIPPED_WHY)
    preset = f" · preset <b>{st.preset}</b>" if st.preset else ""
    changed = st.changed_since_preset()  # the preset's description no longer holds for these
    if changed:
        preset += f" <i>({', '.join(changed)} changed since)</i>"
    flags = key_selection(st.model)
    if flags is not None:
        preset += f" · S = {''.join(map(str, flags))}"
    speed = f"{st.speed:g}×"
    return (
        f'<div style="font-size:0.9em;line-height:1.5">{state}{behind} <b>{model}</b>{preset}<br>'
        f"t = {snap.t:7.2f} s · {rtf}× real time (speed {speed})<br>"
        f'<span style="color:#555">arm: {snap.mode}</span></div>'
    )


def _value(v: float, warn: float, unit: str, digits: int = 3) -> str:
    if not math.isfinite(v):
        return "–"
    colour = WARN_COLOUR if math.isfinite(warn) and v < warn else OK_COLOUR
    if math.isfinite(warn) and v < 0.2 * warn:
        colour = BAD_COLOUR
    return f'<span style="color:{colour};font-weight:600">{v:.{digits}g} {unit}</span>'


def _deflection(snap: Snapshot) -> str:
    """x_b of a 1-DOF base; the tip's translation |(x, y, z)| and rotation |(rx, ry, rz)| of a 6-DOF one."""
    q = snap.q
    if snap.readouts.base_dof <= 1:
        return si(float(q[0]), "m", 1e-9, True)
    m = snap.readouts.base_dof
    text = si(float(np.linalg.norm(q[: min(m, 3)])), "m", 1e-9)
    return text + (f", {si(float(np.linalg.norm(q[3:m])), 'rad', 1e-9)}" if m > 3 else "")


def readouts_html(snap: Snapshot) -> str:
    r = snap.readouts
    if r.dual:
        return _table(dual_rows(snap))
    if r.n is not None:
        n = "(" + ", ".join(f"{v:+.3g}" for v in r.n) + ") kg·m"
    else:
        n = f"{r.rns_dim}-D null space (no single n)"
    err = si(r.ee_error, "m", floor=1e-9)
    rows = [
        (
            "distance to singularity σ<sub>min</sub>(W S H<sub>bm</sub>)",
            _value(r.sigma_hbm, r.warn_hbm, "kg·m"),
            "distance to singularity: how much grip the arm has on the base, near 0 it can neither push nor damp "
            "it; kg·m, a turning base's moment rows (kg·m²) divided by the arm's reach",
        ),
        (
            "hand's freedom σ(J̄)",
            _value(r.sigma_jbar, r.warn_jbar, "m/rad"),
            "how freely the hand can move without pushing the base (J̄ = J P<sub>RNS</sub>)",
        ),
        (
            "reaction-free direction n",
            n,
            "the joint direction that pushes the base not at all (orange arrow: the hand's way), Eq. (27)",
        ),
        (
            f"{MOMENTUM.html_name} = H<sub>bm</sub>θ̇",
            si(r.L, "N·s", 1e-9, True),
            "momentum the joints hand to the base (purple arrow), Eq. (8); 1 N·s = 1 kg·m/s",
        ),
        (BASE_VIBRATION.html_name, _deflection(snap), "how far the base is bent from rest"),
        (HAND_MISS.html_name, err, "how far the hand is from where the law sends it"),
        (
            REACTION.html_name,
            si(r.reaction, "N", 1e-6, True),
            "red arrow: −(H_bm θ'' + c_b), Eq. (1): the arm's push on the base",
        ),
    ]
    return _table(rows)


def _table(rows: list[tuple[str, str, str]]) -> str:
    body = "".join(
        f'<tr title="{hint}"><td style="padding-right:8px">{name}</td><td>{value}</td></tr>'
        for name, value, hint in rows
    )
    return f'<table style="font-size:0.85em;width:100%">{body}</table>'


def dual_rows(snap: Snapshot) -> list[tuple[str, str, str]]:
    """Readouts of a task arm with a compensating arm (Sec. III-B): the compensator's grip on the base,
    whether it cancels the task arm's reaction, and the residual reaction."""
    r = snap.readouts
    if r.cancel is None:
        cancel = f'<span style="color:{OK_COLOUR};font-weight:600">cancelling</span>'
    else:
        cancel = f'<span style="color:{BAD_COLOUR};font-weight:600">{r.cancel}</span>'
    return [
        (
            "distance to singularity σ<sub>min</sub>(W S H<sub>bm,2</sub>)",
            _value(r.sigma_hbm, r.warn_hbm, "kg·m"),
            "the compensating arm's grip on the base; near 0 (its links along the beam's swing) it cannot cancel",
        ),
        ("compensator", cancel, "whether the second arm cancels the task arm's reaction on the base"),
        (
            "task hand's freedom σ<sub>min</sub>(J<sub>1</sub>)",
            _value(r.sigma_jbar, r.warn_jbar, "m/rad"),
            "how freely the task arm's hand moves; near 0 it is stretched out or folded",
        ),
        (
            f"{MOMENTUM.html_name} = S H<sub>bm</sub>θ̇",
            si(r.L, "N·s", 1e-9, True),
            "the momentum both arms hand to the base (purple arrow), Eq. (8): the compensator keeps it 0",
        ),
        (BASE_VIBRATION.html_name, si(float(snap.q[0]), "m", 1e-9, True), "how far the base is bent from rest"),
        (HAND_MISS.html_name, si(r.ee_error, "m", floor=1e-9), "how far the task arm's hand is from the target"),
        (
            REACTION.html_name,
            si(r.reaction, "N", 1e-6, True),
            "red arrow: −(H_bm θ'' + c_b), Eq. (1), of both arms: what the compensator leaves on the base",
        ),
    ]
