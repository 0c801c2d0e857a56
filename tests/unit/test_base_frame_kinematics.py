"""Base-frame kinematics, written once on FsmsModel: the end effector's pose and full Jacobian, the arm's
polyline and a tree's branches, in any pinocchio data. Oracles: finite differences of the pose, the
task-row Jacobian of the laws (ee_kinematics), the links' lengths of the URDF."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.model import FsmsModel

RNG = np.random.default_rng(17)


@pytest.mark.parametrize("name", ["planar3r", "boom7"])
def test_frame_jacobian_is_the_derivative_of_the_pose(name: str, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    data = model.pin_model.createData()
    eps = 1e-6
    for _ in range(5):
        theta = RNG.uniform(np.maximum(model.lower, -np.pi), np.minimum(model.upper, np.pi))
        frame = model.ee_frame_jacobian(theta, data)
        position, rotation = model.ee_pose(theta, data)
        np.testing.assert_array_equal(frame.position, position)
        np.testing.assert_allclose(frame.rotation, rotation, atol=1e-15)
        np.testing.assert_array_equal(position, model.ee_position(theta))
        np.testing.assert_allclose(frame.linear[model.task_rows], model.ee_jacobian(theta), atol=1e-14)
        for k in range(model.n):
            step = np.zeros(model.n)
            step[k] = eps
            (p_plus, R_plus), (p_minus, R_minus) = model.ee_pose(theta + step), model.ee_pose(theta - step)
            np.testing.assert_allclose(frame.linear[:, k], (p_plus - p_minus) / (2 * eps), atol=1e-8)
            omega = pin.log3(R_plus @ R_minus.T) / (2 * eps)  # base frame: R' R^T
            np.testing.assert_allclose(frame.angular[:, k], omega, atol=1e-8)


def test_polylines_run_joint_to_joint_to_the_end_effector(planar3r: FsmsModel, trep2: FsmsModel) -> None:
    model = planar3r
    theta = RNG.uniform(-np.pi, np.pi, 3)
    points = model.arm_points(theta, model.pin_model.createData())
    assert points.shape == (4, 3)
    np.testing.assert_array_equal(points, model.arm_points(theta))
    np.testing.assert_allclose(points[-1], model.ee_position(theta), atol=1e-14)
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    pm = model.pin_model
    links = [np.linalg.norm(pm.jointPlacements[j].translation) for j in (3, 4)]  # joint to joint
    links.append(np.linalg.norm(pm.frames[model.ee_frame_id].placement.translation))  # last joint to hand
    np.testing.assert_allclose(lengths, links, atol=1e-12)  # the URDF's links, whatever the angles
    theta2 = RNG.uniform(-1.0, 1.0, 4)
    task = trep2.branch_points(theta2, "task", trep2.pin_model.createData())
    np.testing.assert_array_equal(task, trep2.branch_points(theta2, "task"))
    np.testing.assert_allclose(task[-1], trep2.ee_position(theta2), atol=1e-14)
