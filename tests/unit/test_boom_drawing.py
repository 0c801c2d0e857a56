"""The boom drawing's geometry (pure numpy): a clamped tube whose tip follows the base joint frame.

Closed forms: at the clamp the centre line starts at the origin along the boom with zero slope; at the
tip it reaches the tip's position with the tip's tangent (rotated by the tip's small rotation), and
its stripe has turned by the tip's twist; the tube's vertices lie at the radius from the line.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.viz.scene.boom_drawing import boom_frames, tube_faces, tube_vertices

L = 4.0
AXES = np.eye(3)  # along x, lateral y and z


@pytest.mark.parametrize(
    ("offset", "phi"),
    [
        (np.zeros(3), np.zeros(3)),
        (np.array([1e-3, 0.05, -0.03]), np.zeros(3)),
        (np.array([0.0, 0.05, 0.0]), np.array([0.0, 0.0, 0.02])),  # bending in y with its slope rz
        (np.array([0.0, 0.0, -0.03]), np.array([0.3, 0.015, 0.0])),  # torsion 0.3 rad, bending in z
    ],
)
def test_the_centre_line_is_clamped_and_meets_the_tip_frame(offset: np.ndarray, phi: np.ndarray) -> None:
    R = pin.exp3(phi)
    line, tangent, normal = boom_frames(L, AXES, offset, R, 41)
    assert np.allclose(line[0], 0.0) and np.allclose(tangent[0], [1.0, 0.0, 0.0])  # clamped: no offset, no slope
    assert np.allclose(line[-1], np.array([L, 0.0, 0.0]) + offset, atol=1e-12)  # the tip is where the frame is
    tip_tangent = R @ np.array([1.0, 0.0, 0.0])
    slope = np.cross(phi, [1.0, 0.0, 0.0])  # the drawn slope is the rotation's first order
    expected = np.array([L + offset[0], L * slope[1], L * slope[2]])
    assert np.allclose(tangent[-1], expected / np.linalg.norm(expected), atol=1e-12)
    assert np.allclose(tangent[-1], tip_tangent, atol=2 * np.linalg.norm(phi) ** 2 + 1e-12)
    assert np.allclose(np.einsum("ij,ij->i", normal, tangent), 0.0, atol=1e-12)
    twist = np.arctan2(normal[-1] @ np.cross([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), normal[-1] @ [0.0, 0.0, 1.0])
    assert twist == pytest.approx(phi[0], abs=np.linalg.norm(phi[1:]) + 1e-12)


def test_tube_vertices_lie_on_the_radius_around_the_line() -> None:
    line, tangent, normal = boom_frames(L, AXES, np.array([0.0, 0.04, 0.01]), pin.exp3(np.array([0.1, 0.0, 0.01])), 25)
    verts = tube_vertices(line, tangent, normal, 0.05, 12).reshape(25, 12, 3)
    radial = verts - line[:, None, :]
    assert np.allclose(np.linalg.norm(radial, axis=2), 0.05)
    assert np.allclose(np.einsum("kjd,kd->kj", radial, tangent), 0.0, atol=1e-12)  # rings across the line
    faces = tube_faces(25, 12)
    assert faces.shape == (2 * 24 * 12, 3) and faces.max() == 25 * 12 - 1
