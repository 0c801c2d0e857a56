"""The panel of a base with several coordinates (boom7: x, y, z, rx, ry, rz): the kick's direction,
the selection S (which reactions must vanish, Sec. III-B) with the reaction null space's dimension
n - r, whether the handle's orientation is tracked too (n - r >= 4: rotational DOF left over), and a
live plot of every base coordinate. Hidden for a 1-DOF base.

The checkboxes make one typed command (:class:`~rns_viz.live.loop.commands.SetSelection`) the loop
applies; what the loop refuses (an RNS the app does not operate) comes back as a notice and the
boxes show the selection in force again.
"""

from __future__ import annotations

import numpy as np
import viser

from rns_viz.defaults import KICK_LEVER_M, defaults_for
from rns_viz.live.published.plot_buffers import BASE_COORDINATES
from rns_viz.live.published.snapshot import Snapshot
from rns_viz.model import FsmsModel
from rns_viz.params import key_selection
from rns_viz.viz.panels.inputs import Controls

COLOURS = ("#1f6fd1", "#e0503a", "#2a9d4b", "#8e44ad", "#c77700", "#555555")
ALL = "all together"


def coordinate_names(model: FsmsModel) -> list[str]:
    """Short names of the base coordinates ("base_rx" -> "rx") with units."""
    joints, turns = model.spec.base.joints, model.base_rotational
    return [f"{j.removeprefix('base_')} ({'mrad' if t else 'mm'})" for j, t in zip(joints, turns, strict=True)]


def kick_weights(turns: tuple[bool, ...], index: int | None) -> tuple[float, ...]:
    """The kick's weights over the base coordinates: along coordinate ``index`` (None: all of them), 1 on a
    translation (the kick's force, N) and KICK_LEVER_M on a rotation (its moment at that lever, N m per N)."""
    return tuple((KICK_LEVER_M if t else 1.0) if index is None or i == index else 0.0 for i, t in enumerate(turns))


class BasePanel:
    def __init__(self, server: viser.ViserServer, controls: Controls, order: float) -> None:
        gui = server.gui
        self.controls = controls
        with gui.add_folder("Base coordinates (spatial)", order=order) as self.folder:
            self.direction = gui.add_dropdown(
                "Kick along",
                ("x",),
                hint="The kick pushes along this base coordinate, or along all of them at once; about a rotation "
                f"it is the moment of the kick's force at {KICK_LEVER_M:g} m (N m). Along the boom's axis (x) it is "
                "very stiff: a sideways kick (y, z) shows the suppression.",
            )
            gui.add_markdown("**Selection S**: tick the base reactions that must vanish (Eq. 8).")
            self.boxes = [gui.add_checkbox(f"S{i + 1}", True) for i in range(BASE_COORDINATES)]
            self.rns = gui.add_markdown("")
            self.orientation = gui.add_checkbox(
                "track orientation",
                False,
                hint="The hand also turns to the handle's orientation (rotation rings), in the RNS directions the "
                "position leaves free (n − r ≥ 4): all three rotations for n − r ≥ 6, fewer by least squares.",
            )
            self.orientation_note = gui.add_markdown("")
            self.involution = gui.add_markdown("")  # the Lie-bracket test of the RNS distribution (Sec. III-A)
            self.plot = gui.add_uplot(
                data=tuple(np.zeros(2) for _ in range(BASE_COORDINATES + 1)),
                series=(
                    {"label": "t (s)"},
                    *({"label": f"c{i + 1}", "stroke": COLOURS[i], "width": 1.5} for i in range(BASE_COORDINATES)),
                ),
                title="Base coordinates (operated run)",
                scales={"x": {"time": False, "auto": True}, "y": {"auto": True}},
                axes=({"size": 28}, {"label": "mm, mrad", "size": 64}),
                legend={"show": True, "live": False},
                cursor={"show": False},
                aspect=2.1,
            )
        self.turns: tuple[bool, ...] = (False,)  # per base coordinate: a rotation (model.base_rotational)
        self.plot_version = -1
        self.overlay_version = -1
        controls.on_input(self.direction, lambda v, c: None)  # read at the next kick
        for box in self.boxes:
            controls.on_input(box, lambda v, c: controls.session.set_selection(self._flags(), c))
        controls.on_input(self.orientation, lambda v, c: controls.session.track_orientation(bool(v), c))
        controls.kick_direction = self.kick_direction

    def _flags(self) -> tuple[bool, ...]:
        return tuple(bool(box.value) for box in self.boxes[: self.m])

    def kick_direction(self) -> tuple[float, ...] | None:
        """The kick's weights over the base coordinates (None for a 1-DOF base)."""
        if self.m == 1:
            return None
        choice = self.controls.good(self.direction)
        options = list(self.direction.options)
        if choice == ALL:
            return kick_weights(self.turns, None)
        return kick_weights(self.turns, options.index(choice) if choice in options else 1)

    @property
    def m(self) -> int:
        """The shown model's base coordinates."""
        return len(self.turns)

    def for_model(self, model: FsmsModel, default_axis: int | None = None) -> None:
        """Show the panel for ``model`` (hidden for a 1-DOF base)."""
        self.turns = model.base_rotational
        self.folder.visible = model.m > 1
        if model.m == 1:
            return
        names = coordinate_names(model)
        with self.controls.quiet():
            self.direction.options = (*(n.split(" ")[0] for n in names), ALL)
        axis = defaults_for(model).kick_axis if default_axis is None else default_axis  # the gain map's kick
        self.controls.show(self.direction, self.direction.options[min(axis, model.m - 1)])
        for i, box in enumerate(self.boxes):
            box.visible = i < model.m
            if i < model.m:
                box.label = names[i].split(" ")[0]
        self.plot_version = -1

    def sync(self, snap: Snapshot, model: FsmsModel) -> None:
        """Show the selection in force and the RNS dimension it leaves."""
        if self.m == 1:
            return
        flags = key_selection(snap.settings.model) or tuple(int(f) for f in model.spec.base.selection)
        for box, flag in zip(self.boxes, flags, strict=False):
            self.controls.show(box, bool(flag))
        r = sum(flags)
        n = model.n
        turning = snap.orientation is not None and snap.orientation.on
        what = (
            "a 1-D reaction null space: the arm moves without reaction only along its reactionless path "
            "(scrub ū or drag the handle)"
            if n - r == 1
            else f"a {n - r}-D reaction null space: drag the handle in 3-D, the hand tracks it "
            + ("and its orientation in the RNS (task priority)" if turning else "by Eq. (24)")
        )
        self.rns.content = f"r = {r} of {model.m}; n − r = {n} − {r} = **{n - r}**: {what}."
        view = snap.orientation
        self.orientation.visible = self.orientation_note.visible = view is not None
        if view is not None:
            self.controls.show(self.orientation, view.on)
            self.orientation.disabled = not view.offered
            self.orientation_note.content = view.note

    def update(self, arrays: dict[str, np.ndarray], version: int) -> None:
        """Send the base coordinates of the operated run (plot buffers in mm / mrad), and the integrability
        of the RNS distribution once a new reachable set arrived."""
        if self.m == 1:
            return
        overlays = self.controls.session.overlays()
        if overlays.version != self.overlay_version:
            self.overlay_version = overlays.version
            text = f"**Reachable set** ({len(overlays.reach)} points drawn). " if overlays.reach is not None else ""
            self.involution.content = text + overlays.reach_note
        if version == self.plot_version:
            return
        self.plot_version = version
        if len(arrays["t"]) < 2:  # a restarted run: the last one's curves go
            self.plot.data = tuple(np.zeros(2) for _ in range(BASE_COORDINATES + 1))
            return
        columns = [np.nan_to_num(arrays[f"xb_{i + 1}"]) for i in range(BASE_COORDINATES)]
        self.plot.data = (arrays["t"], *columns)
