"""The *Show in the scene* folder: one checkbox per thing the eye can't see, each with units in its hint.

These are drawing choices of the server's one scene, read by the render thread each frame; they send
no command to the session. Only the operator may change them (a watcher's change is set back).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import viser

from rns_viz.defaults import defaults_for
from rns_viz.live.operator.kinds import operator_class
from rns_viz.live.teaching.rank_view import RANK_HINT
from rns_viz.model import FsmsModel
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.scene.quantities import MOMENTUM, REACTION

# (field, label, initial, hint): the hints are what a student reads on hovering.
TOGGLES: tuple[tuple[str, str, bool, str], ...] = (
    (
        "labels",
        "Labels (names in the scene)",
        True,
        "The names written in the scene: base, clamp, spring, 'drag me', the ghost's.",
    ),
    (
        "paths",
        "Other reactionless paths (grey)",
        False,
        "The family of reactionless paths around the current one (crimson, always drawn): every way the hand can "
        "move without pushing the base, from other start poses.",
    ),
    (
        "gain_map",
        "Gain map (which gains damp fastest)",
        False,
        "A map of (g_b, g_m) settings coloured by how fast the base's swing dies out, above the robot; click a "
        "cell to apply its gains. The Gain explorer folder explains it.",
    ),
    (
        "ghost",
        "Ghost: the shadow run",
        True,
        "A second simulation with the same kicks and inputs but vibration suppression the other way, "
        "drawn see-through over the arm: blue when its run has suppression on, red when off (as the plots).",
    ),
    (
        "reaction",
        f"{REACTION.name.capitalize()} ({REACTION.unit})",
        True,
        "Red arrow: the force the arm's motion puts on the base, −(H_bm θ'' + c_b) of Eq. (1), in newtons (N).",
    ),
    (
        "coupling",
        f"{MOMENTUM.name.capitalize()} ({MOMENTUM.unit})",
        True,
        "Purple arrow: the momentum the arm's joint motion hands to the base, L = H_bm θ' (Eq. 8), in N·s "
        "(1 N·s = 1 kg·m/s). Zero on a reactionless path.",
    ),
    (
        "null_vector",
        "Reaction-free direction n (m/s per unit ū)",
        True,
        "Orange arrow at the hand: where the hand goes when the joints turn along n, the one direction "
        "that pushes the base not at all (Eq. 27); its length is J n, m/s per unit of ū.",
    ),
    ("trail", "End-effector trail", True, "Green line: where the hand has been, relative to the base (m)."),
    (
        "path_arrows",
        "Path direction arrows",
        True,
        "Arrowheads on the crimson reactionless path pointing the way the arm moves when ū is positive.",
    ),
    (
        "reach",
        "Reactionless-reachable region",
        True,
        "Lilac dots: where the hand can go without ever pushing the base (a reaction null space of two or "
        "more dimensions). The region ends at fold curves, where the arm can no longer move the hand "
        "outward without moving its centre of mass along the base's swing (J-bar loses rank).",
    ),
    (
        "rank",
        "Rank loss of H_bm",
        False,
        "Amber poses (Sec. III-B, the fourth case). " + RANK_HINT,
    ),
)


@dataclass
class ViewToggles:
    """The checkboxes, by field name; ``on(name)`` is what the render thread reads."""

    boxes: dict[str, viser.GuiCheckboxHandle]
    good: dict[str, bool] = field(default_factory=dict)  # the values in force (a hostile value is set back)

    def on(self, name: str) -> bool:
        box = self.boxes.get(name)
        return True if box is None else box.value is True and not box.disabled

    def show(self, name: str, on: bool = True) -> None:
        """Tick or untick one toggle, as the server (the map for a gain lesson, a test); a toggle disabled for
        the model stays unticked."""
        on = on and not (name in self.boxes and self.boxes[name].disabled)
        self.good[name] = on
        if name in self.boxes and self.boxes[name].value != on:
            self.boxes[name].value = on

    def show_only(self, names: Iterable[str]) -> None:
        """Tick exactly ``names`` (a lesson's view), as the server: no refusal, no callback work."""
        wanted = set(names)
        for name, box in self.boxes.items():
            self.good[name] = name in wanted and not box.disabled
            if box.value != self.good[name]:
                box.value = self.good[name]

    def fit(self, model: FsmsModel) -> None:
        """Disable (and untick) the toggles that draw nothing on ``model``, their hints saying why; enable the rest."""
        why = nothing_to_show(model)
        hints = {name: hint for name, _, _, hint in TOGGLES}
        for name, box in self.boxes.items():
            box.disabled = name in why
            box.hint = f"{why[name]} {hints[name]}" if name in why else hints[name]
            if name in why:
                self.show(name, False)


def nothing_to_show(model: FsmsModel) -> dict[str, str]:
    """The toggles that cannot show anything on ``model``, each with the reason in plain words: the path
    overlays need a single reactionless path (a 1-D reaction null space, Sec. III), the reachable region a
    larger one, and the gain map a model whose gains the explorer analyses (not a compensating arm's)."""
    kind = operator_class(model)
    if kind.compensates:
        no_path = "Not for this model: a second arm cancels the task arm's reaction, so no reactionless path is traced."
    else:
        no_path = (
            "Not for this model: its reaction null space has two or more dimensions, so there is no single "
            "reactionless path (the reachable region shows where the hand can go instead)."
        )
    why: dict[str, str] = {}
    if kind.shows != "path":
        why |= dict.fromkeys(("paths", "null_vector", "path_arrows"), no_path)
    if kind.shows != "reachable set":
        why["reach"] = (
            "Not for this model: a second arm cancels the task arm's reaction, so the hand goes anywhere it reaches."
            if kind.compensates
            else "Not for this model: its reaction null space is one-dimensional, so the hand moves only along "
            "its reactionless path."
        )
    if kind.compensates:
        why["gain_map"] = (
            "Not for this model: the gain map is computed for one arm damping the base's swing, not for a second "
            "arm that cancels the reaction."
        )
    return why


def first_look(model: FsmsModel) -> frozenset[str]:
    """What ``model``'s scene shows at first: its parameter file's ``[app.scene] shown``, and the
    reactionless-reachable set whenever the operator drives a target over it (a selection S that leaves a
    reaction null space of two or more dimensions): where the target can go is what the operator needs."""
    shown = defaults_for(model).shown
    return (shown | {"reach"}) if operator_class(model).shows == "reachable set" else shown


def make_view_toggles(gui: viser.GuiApi, connections: Connections, shown: Iterable[str] | None = None) -> ViewToggles:
    """The folder, ticked as ``shown`` (the model's defaults; None: each toggle's own initial value); a
    watcher's change (or a value that is not a bool) is set back and reported."""
    on = None if shown is None else set(shown)
    with gui.add_folder("Show in the scene", expand_by_default=False):
        boxes = {
            name: gui.add_checkbox(label, initial if on is None else name in on, hint=hint)
            for name, label, initial, hint in TOGGLES
        }
    good = {name: box.value for name, box in boxes.items()}

    def wire(name: str, box: viser.GuiCheckboxHandle) -> None:
        @box.on_update
        def _(event: viser.GuiEvent) -> None:
            if box.value == good[name]:
                return
            if isinstance(box.value, bool) and not box.disabled and connections.allowed(event.client):
                good[name] = box.value
                return
            if not connections.allowed(event.client):
                connections.refuse_watcher(event.client)
            box.value = good[name]

    for name, box in boxes.items():
        wire(name, box)
    return ViewToggles(boxes, good)
