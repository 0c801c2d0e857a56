"""The app's callouts: the base's name, "drag me" at the target handle and the ghost's name at its hand,
placed off both arms."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import viser

from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.scene.callout_layout import PageCamera
from rns_viz.viz.scene.callouts import FixedText, page_camera
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.scene.ghost import Ghost

HANDLE_CLEAR = 0.45  # of the handle's scale: the cube about it that no label covers (its arrows and square)


class SceneCallouts:
    """Places and draws the callouts each frame for the pages connected (the operator's page first)."""

    def __init__(
        self,
        server: viser.ViserServer,
        scene: FsmsScene,
        ghost: Ghost,
        handle: viser.TransformControlsHandle | None,
        connections: Connections | None,
        notice: Callable[[int], bool] = lambda client_id: False,
        texts: Callable[[], Sequence[FixedText]] = lambda: (),
    ) -> None:
        """``handle`` None: no "drag me"; ``connections`` None (a recording's export): no pages, so every
        label is drawn at its point; ``notice(client_id)``: the page's panel shows the slowed-display line;
        ``texts()``: the other labels written in the scene (the gain map's title and legend)."""
        self.server, self.scene, self.ghost, self.handle, self.connections = server, scene, ghost, handle, connections
        self.notice, self.texts = notice, texts
        self.callouts = scene.callouts  # the base's callout is the scene's own
        self.drag = None
        if handle is not None:  # its frame: the handle's parent (FsmsScene.BASE_AT_REST), its point: the handle
            clear = HANDLE_CLEAR * handle.scale
            self.drag = self.callouts.add("drag_me", "drag me", parent=FsmsScene.BASE_AT_REST, keep_clear=clear)
        model = ghost.model
        hand = model.pin_model.frames[model.ee_frame_id]  # the ghost's hand: the end-effector frame on its joint
        self.hand_joint, self.hand_point = hand.parentJoint, np.array(hand.placement.translation, dtype=float)
        self.ghost_name = self.callouts.add("ghost", ghost.label_text, parent=ghost.robot.node_names[self.hand_joint])
        self.rest = scene.robot.rest_base_placement()  # the handle's parent frame (FsmsScene.BASE_AT_REST)

    def frame(self, now: float, labels_on: bool) -> None:
        self.scene.attach_base_callout()
        if self.drag is not None and self.handle is not None:
            self.drag.attach(self.rest.rotation, self.rest.translation, np.asarray(self.handle.position, dtype=float))
            self.drag.shown = bool(self.handle.visible)
        self.ghost_name.shown = bool(self.ghost.root.visible)
        self.ghost_name.text = self.ghost.label_text
        if self.ghost_name.shown:
            hand = self.ghost.robot.data.oMi[self.hand_joint]
            self.ghost_name.attach(hand.rotation, hand.translation, self.hand_point)
        self.callouts.frame(now, self.pages, self.solids, labels_on, self.texts)

    def pages(self) -> list[PageCamera]:
        """The pages' cameras, the operator's first (then by connection order)."""
        if self.connections is None:
            return []
        allowed = self.connections.allowed
        clients = sorted(self.server.get_clients().items())
        clients.sort(key=lambda item: not allowed(item[1]))
        cameras = (page_camera(client, self.notice(client_id)) for client_id, client in clients)
        return [cam for cam in cameras if cam is not None]

    def solids(self) -> np.ndarray:
        """World corners (L, 8, 3) of every visual box of the robot's arm, of the ghost's when it is shown, and
        of what the view frames beside the robot (the gain map with its title, ticks and legend, while shown):
        no label covers a cell of the map."""
        parts = [self.scene.robot.link_corners()]
        if self.ghost.root.visible:
            parts.append(self.ghost.robot.link_corners())
        beside, corners = self.scene.also_framed, parts[0].shape[1]
        if beside is not None and len(beside) and corners:  # one solid: its corners repeated to a link's count
            parts.append(np.resize(beside, (1, corners, 3)))
        return np.concatenate(parts)
