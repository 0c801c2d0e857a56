"""The robot's URDF visuals in viser, posed from pinocchio's forward kinematics.

Meshes come from yourdfpy (the same URDF pinocchio reads). The viser node tree mirrors the
kinematic tree: base joints are world-posed nodes (the last one is ``base_name``, so overlays given
in the base frame can hang under it), each arm joint is a child node of its parent joint posed by
pinocchio's ``liMi``. Fixed links (the end effector) have their meshes moved into the parent
joint's node, so they cost nothing per frame. A pose is only sent when it changed: a planar arm
sends one orientation per arm joint and one base position per frame. (Each viser pose setter costs
~50 us because it runs ``np.allclose``; ``ViserUrdf.update_cfg`` walks yourdfpy's scene graph.)
A URDF's meshes are read once per file (the robot and its ghost share them; the Panda's .dae meshes
take a second or two to read); each drawing places copies.
"""

from __future__ import annotations

import threading
from functools import lru_cache, partial
from pathlib import Path

import numpy as np
import pinocchio as pin
import trimesh
import viser
import yourdfpy

from rns_viz.model import FsmsModel

_LOADING = threading.Lock()


@lru_cache(maxsize=4)
def _load_urdf(path: Path, mtime_ns: int) -> yourdfpy.URDF:
    """The URDF with its visual meshes, read once per file version (``mtime_ns``); callers copy meshes."""
    return yourdfpy.URDF.load(
        str(path),
        build_scene_graph=True,
        load_meshes=True,
        filename_handler=partial(yourdfpy.filename_handler_magic, dir=path.parent),
    )


class RobotMeshes:
    """One frame node per pinocchio joint, the URDF visuals under the joint that carries them."""

    def __init__(
        self, server: viser.ViserServer, model: FsmsModel, base_name: str = "/base", root: str = "/robot"
    ) -> None:
        path = model.spec.urdf_path
        pm = model.pin_model
        with _LOADING:  # the cached URDF is shared: one reader at a time
            urdf = _load_urdf(path, path.stat().st_mtime_ns)
            joint_links = {name: urdf.joint_map[name].child for name in pm.names[1:]}
            scene = urdf.scene
            visuals = []  # (link, mesh in its link's frame)
            for geom_name, mesh in scene.geometry.items():
                link = scene.graph.transforms.parents[geom_name]
                local = mesh.copy()
                local.apply_transform(urdf.get_transform(geom_name, link))
                visuals.append((link, geom_name, local))
        self.model = model
        self.data = pm.createData()  # own data: the simulation thread may be using model.data
        self.node_names = [root] + [""] * (pm.njoints - 1)
        for j in range(1, pm.njoints):
            link = joint_links[pm.names[j]]
            if j < model.m:
                self.node_names[j] = f"{root}/{link}"
            elif j == model.m:
                self.node_names[j] = base_name
            else:
                self.node_names[j] = f"{self.node_names[pm.parents[j]]}/{link}"
        server.scene.add_frame(root, show_axes=False)
        self.frames = [server.scene.add_frame(name, show_axes=False) for name in self.node_names[1:]]
        self._world_posed = model.m  # joints 1..m are posed in the world, the rest relative to parents
        self._last: list[tuple[tuple[float, ...], tuple[float, ...]] | None] = [None] * len(self.frames)
        self.meshes: list[viser.SceneNodeHandle] = []
        self._boxes: list[tuple[int, np.ndarray]] = []  # (joint, the 8 corners of a visual's box in its frame)
        carrying = {model.m}  # joints whose node carries visuals: the base node (and its children) always
        for link, geom_name, local in visuals:
            frame = pm.frames[pm.getFrameId(link)]
            local.apply_transform(frame.placement.homogeneous)
            node = self.node_names[frame.parentJoint]
            carrying.add(frame.parentJoint)
            if frame.parentJoint >= model.m:  # the arm and its mount: what a label must not cover
                (x0, y0, z0), (x1, y1, z1) = local.bounds
                box = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)])
                self._boxes.append((frame.parentJoint, box))
            self.meshes.append(self._add_mesh(server, f"{node}/{link}_{geom_name}", local))
        # Base joints before the last are world-posed nodes of their own; one without visuals (boom7's
        # massless links between its six tip coordinates) shows nothing, so its pose is never sent.
        self._posed = [j > model.m or j in carrying for j in range(1, pm.njoints)]

    def _add_mesh(self, server: viser.ViserServer, name: str, mesh: trimesh.Trimesh) -> viser.SceneNodeHandle:
        """One visual; a subclass may draw it otherwise (the ghost: one translucent colour)."""
        return server.scene.add_mesh_trimesh(name, mesh)

    def pose(self, q: np.ndarray) -> None:
        """Forward kinematics at ``q`` (pinocchio order); send the joint poses that changed."""
        pm, data = self.model.pin_model, self.data
        pin.forwardKinematics(pm, data, q)
        for i, handle in enumerate(self.frames):
            if not self._posed[i]:
                continue
            j = i + 1
            M = data.oMi[j] if j <= self._world_posed else data.liMi[j]
            position = tuple(M.translation.tolist())
            quat = pin.Quaternion(M.rotation)
            wxyz = (quat.w, quat.x, quat.y, quat.z)
            last = self._last[i]
            if last is None or last[0] != position:
                handle.position = position
            if last is None or last[1] != wxyz:
                handle.wxyz = wxyz
            self._last[i] = (position, wxyz)

    def base_placement(self) -> pin.SE3:
        """World placement of the last base joint after :meth:`pose` (the base frame)."""
        return self.data.oMi[self.model.m]

    def rest_base_placement(self) -> pin.SE3:
        """World placement of the last base joint with the base undeflected (every base coordinate at rest)."""
        pm = self.model.pin_model
        data = pm.createData()
        pin.forwardKinematics(pm, data, pin.neutral(pm))
        return data.oMi[self.model.m].copy()

    @property
    def base_node(self) -> viser.FrameHandle:
        """The node that follows the last base joint; children are in the base frame."""
        return self.frames[self.model.m - 1]

    def link_corners(self) -> np.ndarray:
        """World corners (J, 8 k, 3) of the boxes of the visuals each joint of the arm and its mount carries (k
        boxes, repeated to the largest k), as last posed, m: one solid per link."""
        if not self._boxes:
            return np.zeros((0, 8, 3))
        joints = sorted({j for j, _ in self._boxes})
        per_joint = [np.concatenate([box for j, box in self._boxes if j == joint]) for joint in joints]
        most = max(len(c) for c in per_joint)
        out = np.empty((len(joints), most, 3))
        for row, (joint, corners) in enumerate(zip(joints, per_joint, strict=True)):
            M = self.data.oMi[joint]
            world = corners @ M.rotation.T + M.translation
            out[row] = np.concatenate([world, np.repeat(world[-1:], most - len(world), axis=0)])
        return out

    def ee_position(self, offset: np.ndarray | None = None) -> np.ndarray:
        """World position of the end effector (plus ``offset`` in the base frame) after :meth:`pose`, m."""
        ee = pin.updateFramePlacement(self.model.pin_model, self.data, self.model.ee_frame_id).translation
        return ee if offset is None else ee + self.base_placement().rotation @ offset
