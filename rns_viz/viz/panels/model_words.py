"""What the panel says about the model served: headings, explanations and hints that name only what
applies to it (no other model's name, no "x and y only" for a handle that moves in 3-D).

Pure functions of the model; the renderer shows them whenever it builds a model's scene.
"""

from __future__ import annotations

from rns_viz.defaults import defaults_for
from rns_viz.live.operator.kinds import operator_class
from rns_viz.model import FsmsModel


def target_text(model: FsmsModel) -> str:
    """How the target handle works for ``model``: in the plane or in 3-D, clamped to the reachable set or
    followed by a task arm whose reaction a second arm cancels."""
    spatial = len(model.task_rows) == 3
    drag = "Drag the handle labelled **drag me** " + ("in 3-D (x, y and z)" if spatial else "(x and y only)")
    if operator_class(model).compensates:
        return (
            f"{drag}: the task arm follows anywhere in its workspace; the second arm cancels its reaction on the base."
        )
    return (
        f"{drag}: the hand follows with reactionless end-effector control, Eq. (24); targets outside the "
        "reactionless reachable set (the small lilac dots; the larger yellow-to-purple dots on it are the gain "
        "explorer's authority) are held at its nearest point."
    )


def kick_hint(model: FsmsModel) -> str:
    """The kick slider's hint: the pulse of this model (its duration) and, for a base of several
    coordinates, where its direction is chosen."""
    duration = defaults_for(model).kick_duration_s
    hint = f"Peak of the half-sine force pulse on the base ({duration:g} s long), N"
    if model.m > 1:
        hint += "; along the direction chosen under Base coordinates (N m on a rotation)"
    return hint + "."
