"""The rank-deficiency overlay (Sec. III-B, the fourth case) for TREP and the planar 3R.

Every drawn pose is a configuration where S H_bm has lost rank: sigma_min <= 1e-9 of ||S H_bm|| in the
most coupled configuration of the search grid, recomputed here from the model; for one base row that
means every link along the deflection axis x (the coupling row is the arm's mass-weighted motion along
x), so every drawn point lies on y = 0; and there a joint velocity along the kernel gives no coupling.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.live.teaching.rank_view import rank_overlay
from rns_viz.model import FsmsModel
from rns_viz.rank import kernel_coupling


@pytest.mark.parametrize(("name", "count"), [("trep", 4), ("planar3r", 8)])
def test_every_drawn_pose_has_lost_rank(name: str, count: int, bundled_model: Callable[[str], FsmsModel]) -> None:
    model = bundled_model(name)
    overlay = rank_overlay(name)
    assert overlay is not None
    assert len(overlay.poses) == count  # links folded or stretched along x: 2^n poses
    assert overlay.scale > 0.0
    for theta, pose in zip(overlay.theta, overlay.poses, strict=True):
        sigma = np.linalg.svd(model.coupling_matrix(model.q(theta)), compute_uv=False)[-1]
        assert sigma <= 1e-9 * overlay.scale
        np.testing.assert_allclose(pose, model.arm_points(theta), atol=1e-15)
        np.testing.assert_allclose(pose[-1], model.ee_position(theta), atol=1e-12)
        assert np.abs(pose[:, 1]).max() < 1e-9  # every point of the drawn pose on the deflection axis
        assert kernel_coupling(model, theta)[0] <= 1e-9 * overlay.scale  # kernel velocity: no coupling


def test_no_overlay_for_the_dual_arm_model() -> None:
    assert rank_overlay("trep2") is None
