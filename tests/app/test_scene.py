"""The viser scene on a server, no browser: its nodes, the arm posed and the base drawn, the path family,
reachable set, target, force and trail (its pure geometry: tests/unit/test_scene.py)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator

import numpy as np
import pytest
import viser

from rns_viz.model import FsmsModel
from rns_viz.paths import path_family
from rns_viz.viz import FsmsScene
from rns_viz.viz.scene.base_drawing import CartSpringDrawing, DoubleBeamDrawing
from rns_viz.viz.scene.fsms_scene import PATH_HIGHLIGHT
from tests.support.drawing import distance_to_segments


@pytest.fixture(scope="module")
def server() -> Iterator[viser.ViserServer]:
    srv = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield srv
    srv.stop()


@pytest.fixture
def trep_scene(server: viser.ViserServer, trep: FsmsModel) -> FsmsScene:
    server.scene.reset()
    return FsmsScene(server, trep)


@pytest.fixture
def planar_scene(server: viser.ViserServer, planar3r: FsmsModel) -> FsmsScene:
    server.scene.reset()
    return FsmsScene(server, planar3r)


@pytest.mark.parametrize("name", ["trep", "planar3r"])
def test_scene_builds_with_its_nodes(
    server: viser.ViserServer, name: str, bundled_model: Callable[[str], FsmsModel]
) -> None:
    server.scene.reset()
    model = bundled_model(name)
    scene = FsmsScene(server, model)
    base_node = "/beam/plates" if name == "trep" else "/spring/coil"
    for node in (FsmsScene.BASE, FsmsScene.PATHS, FsmsScene.TRAIL, FsmsScene.FORCE, FsmsScene.GRID, base_node):
        assert server.scene.get_handle_by_name(node) is not None, node
    assert len(scene.robot.meshes) >= model.n  # every arm link has a visual
    # the initial camera looks at the framed box's centre along the style's view direction
    cam = server.initial_camera
    assert np.allclose(cam.look_at, scene.framed.mean(axis=0))
    view = np.subtract(cam.position, cam.look_at)
    style_view = np.subtract(scene.style.camera_position, scene.style.camera_look_at)
    assert np.allclose(view / np.linalg.norm(view), style_view / np.linalg.norm(style_view))


def test_update_bends_the_beam_by_exaggerated_deflection(trep_scene: FsmsScene, trep: FsmsModel) -> None:
    x_b, exaggeration = 0.003, 20.0
    trep_scene.update(trep.q(trep.spec.default_configuration, [x_b]), exaggeration)
    drawn = exaggeration * x_b
    assert np.allclose(trep_scene.base_node.position, [drawn, 0.5, 0.0])
    beam = trep_scene.base_drawing
    assert isinstance(beam, DoubleBeamDrawing)
    lines = beam.centrelines(beam.x_b)  # (plates, stations, 3)
    assert np.allclose(lines[:, -1, 0], [drawn - 0.05, drawn + 0.05])  # guided tip moves with the base
    assert np.allclose(lines[:, 0, 0], [-0.05, 0.05])  # clamped root stays
    mid = beam.style.stations // 2
    assert np.allclose(lines[:, mid, 0] - [-0.05, 0.05], 0.5 * drawn)  # u(L/2) = x_b (3/4 - 2/8)
    verts = np.asarray(beam.mesh.vertices).reshape(2, beam.style.stations, 2, 3)
    assert np.allclose(verts[:, -1, :, 0], np.array([[drawn - 0.05] * 2, [drawn + 0.05] * 2]), atol=1e-6)


def test_update_poses_the_arm_from_pinocchio(trep_scene: FsmsScene, trep: FsmsModel) -> None:
    theta = np.array([0.4, -1.1])
    trep_scene.update(trep.q(theta, [0.002]), 10.0)
    ee = trep_scene.robot.ee_position()
    assert np.allclose(ee, trep.ee_position(theta) + np.array([0.02, 0.5, 0.0]))
    link1 = trep_scene.server.scene.get_handle_by_name("/base/link1")
    assert link1 is not None
    assert np.allclose(abs(link1.wxyz[0]), np.cos(0.2)) and np.allclose(abs(link1.wxyz[3]), np.sin(0.2))


def test_update_rejects_a_wrong_configuration(trep_scene: FsmsScene) -> None:
    with pytest.raises(ValueError, match="shape"):
        trep_scene.update(np.zeros(2), 1.0)


def test_cart_and_spring_follow_the_base(planar_scene: FsmsScene, planar3r: FsmsModel) -> None:
    planar_scene.update(planar3r.q(planar3r.spec.default_configuration, [0.1]), 3.0)
    assert np.allclose(planar_scene.base_node.position, [0.3, 0.0, 0.0])
    spring = planar_scene.base_drawing
    assert isinstance(spring, CartSpringDrawing)
    points = np.asarray(spring.spring.points)
    assert np.allclose(points[0, 0], spring.anchor, atol=1e-6)
    assert np.allclose(points[-1, 1], [0.3 + spring.attach[0], 0.0, spring.attach[2]], atol=1e-6)


def _drawn_path(points: np.ndarray, is_path: np.ndarray) -> np.ndarray:
    """The drawn segments of one path, checked to join end to start."""
    mine = points[is_path]
    assert np.allclose(mine[1:, 0], mine[:-1, 1])
    return mine


def test_path_family_is_one_node_with_the_current_path_highlighted(trep_scene: FsmsScene, trep: FsmsModel) -> None:
    paths = path_family(trep, 12)
    trep_scene.set_path_family(paths, 3)
    points, colours = np.asarray(trep_scene.paths.points), np.asarray(trep_scene.paths.colors)
    assert colours.shape == points.shape and points.shape[1:] == (2, 3)
    assert len(points) < sum(min(len(p.ee), trep_scene.style.path_points) - 1 for p in paths)  # simplified
    highlight = (np.array(PATH_HIGHLIGHT) * 255).astype(np.uint8)
    is_current = np.all(colours == highlight, axis=(1, 2))
    assert np.all(is_current[-is_current.sum() :])  # drawn last, on top
    tolerance = trep_scene.style.path_tolerance
    drawn, ee = _drawn_path(points, is_current), paths[3].ee
    assert np.allclose(drawn[0, 0], ee[0], atol=1e-6) and np.allclose(drawn[-1, 1], ee[-1], atol=1e-6)
    assert distance_to_segments(drawn[:, 0], ee[:, None, :].repeat(2, axis=1)).max() < 1e-6  # its own points
    assert distance_to_segments(ee, drawn).max() <= tolerance + 1e-6  # and never farther than the tolerance
    trep_scene.set_current_path(5)  # recolour only
    is_current = np.all(np.asarray(trep_scene.paths.colors) == highlight, axis=(1, 2))
    drawn = _drawn_path(points, is_current)
    assert np.allclose(drawn[0, 0], paths[5].ee[0], atol=1e-6) and np.allclose(drawn[-1, 1], paths[5].ee[-1], atol=1e-6)
    assert distance_to_segments(paths[5].ee, drawn).max() <= tolerance + 1e-6
    with pytest.raises(IndexError):
        trep_scene.set_path_family(paths, len(paths))


def test_reachable_set_target_and_force(planar_scene: FsmsScene) -> None:
    points = np.random.default_rng(0).uniform(-2, 2, (500, 3))
    planar_scene.set_reachable_set(points)
    assert planar_scene.reachable.visible and np.asarray(planar_scene.reachable.points).shape == (500, 3)
    planar_scene.set_reachable_set(None)
    assert not planar_scene.reachable.visible
    planar_scene.set_target(np.array([1.0, 0.5, 0.0]))
    assert planar_scene.target.visible and np.allclose(planar_scene.target.position, [1.0, 0.5, 0.0])
    st = planar_scene.style
    planar_scene.set_reaction_force(40.0)
    arrow = np.asarray(planar_scene.force.points)[0]
    assert planar_scene.force.visible and np.isclose(arrow[1, 0] - arrow[0, 0], 40.0 * st.force_scale)
    planar_scene.set_reaction_force(-1e6)  # clipped, pointing the other way
    arrow = np.asarray(planar_scene.force.points)[0]
    assert np.isclose(arrow[1, 0] - arrow[0, 0], -st.force_arrow_max)
    planar_scene.set_reaction_force(0.0)
    assert not planar_scene.force.visible


def test_scene_trail_follows_the_end_effector(trep_scene: FsmsScene, trep: FsmsModel) -> None:
    trep_scene.clear_trail()
    for t in np.linspace(0.0, 1.0, 50):
        trep_scene.update(trep.q([np.pi / 2 + t, 0.0]), 1.0)
    segs = np.asarray(trep_scene.trail_node.points)
    assert trep_scene.trail_node.visible and 10 < len(segs) < trep_scene.style.trail_capacity
    assert np.allclose(np.linalg.norm(segs[:, :, :2] - [0.0, 0.5], axis=-1), 0.2, atol=1e-5)  # a circle arc


@pytest.mark.perf
def test_update_is_cheap(trep_scene: FsmsScene, trep: FsmsModel) -> None:
    """60 Hz leaves 16 ms a frame; the scene's share should stay near 1 ms (bound loose for CI)."""
    q = trep.q(trep.spec.default_configuration)
    times = []
    for k in range(300):
        q[0], q[1] = 0.003 * np.sin(0.1 * k), 1.0 + 0.01 * k
        start = time.perf_counter()
        trep_scene.update(q, 10.0)
        times.append(time.perf_counter() - start)
    assert np.median(times) < 5e-3


def test_base_frame_trail_ignores_base_motion(server: viser.ViserServer, trep: FsmsModel) -> None:
    lengths = {}
    for frame in ("world", "base"):
        server.scene.reset()
        scene = FsmsScene(server, trep, trail_frame=frame)
        for x_b in np.linspace(0.0, 0.004, 20):  # the base moves, the arm does not
            scene.update(trep.q(trep.spec.default_configuration, [x_b]), 10.0)
        lengths[frame] = len(scene.trail)
    assert server.scene.get_handle_by_name(FsmsScene.BASE_TRAIL) is not None
    assert lengths["world"] > 5 and lengths["base"] == 1
