"""The joint-space inset of rank loss (Sec. III-B, the fourth case) for TREP and the planar 3R.

Every rank-loss marker it draws is a configuration where sigma_min(S H_bm) <= 1e-9 of the most coupled
||S H_bm||, recomputed here from the model, and motion along the kernel there gives no coupling; the
markers and the arm's dot land on the picture where their joint angles are (read back from the
pixels). In the app: tests/app/test_rank_inset.py.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from rns_viz.live.teaching.rank_view import inset_slice, rank_inset
from rns_viz.model import FsmsModel
from rns_viz.rank import kernel_coupling
from rns_viz.viz.panels.rank_inset import DOT_COLOUR, InsetPicture, dot_pixel, draw_inset, with_dot

PLANES = [("trep", np.array([1.2, -0.4]), 4), ("planar3r", np.array([0.0, 0.5, -1.0]), 4)]


def _sigma_min(model: FsmsModel, theta: np.ndarray) -> float:
    return float(np.linalg.svd(model.coupling_matrix(model.q(theta)), compute_uv=False)[-1])


@pytest.mark.parametrize(("name", "theta", "filled"), PLANES)
def test_every_drawn_marker_has_lost_rank_and_the_field_is_sigma_min(
    name: str, theta: np.ndarray, filled: int, bundled_model: Callable[[str], FsmsModel]
) -> None:
    model = bundled_model(name)
    data = rank_inset(name, inset_slice(name, theta))
    assert data is not None and data.scale > 0.0
    assert int(data.in_plane.sum()) == filled  # TREP: all 4; the 3R at theta_1 = 0: 4 of its 8
    for config in data.theta:
        assert _sigma_min(model, config) <= 1e-9 * data.scale
        assert kernel_coupling(model, config)[0] <= 1e-9 * data.scale
    if model.n == 3:  # a filled marker lies in the drawn plane theta_1 = slice, a ring does not
        delta = np.abs(np.angle(np.exp(1j * (data.theta[:, 0] - data.fixed))))
        assert np.all(delta[data.in_plane] < 1e-6) and np.all(delta[~data.in_plane] > 1.0)
    rng = np.random.default_rng(3)
    for i, j in rng.integers(0, data.axis.size, (5, 2)):  # the field: sigma_min at the grid node, normalised
        config = model.spec.default_configuration.copy()
        if data.fixed is not None:
            config[0] = data.fixed
        config[list(data.columns)] = data.axis[i], data.axis[j]
        assert data.sigma[i, j] == pytest.approx(_sigma_min(model, config) / data.scale, rel=1e-9, abs=1e-15)


def _is_colour(pixel: np.ndarray, colour: tuple[int, int, int], tol: int = 40) -> bool:
    return bool(np.all(np.abs(pixel.astype(int) - np.array(colour)) <= tol))


@pytest.mark.parametrize(("name", "theta", "filled"), PLANES)
def test_markers_and_the_dot_land_where_their_joint_angles_are(name: str, theta: np.ndarray, filled: int) -> None:
    data = rank_inset(name, inset_slice(name, theta))
    assert data is not None
    picture: InsetPicture = draw_inset(data, ("a", "b"), "t")
    for config in data.theta[data.in_plane]:  # a filled amber marker under each in-plane configuration
        col, row = dot_pixel(picture, config)
        assert _is_colour(picture.image[round(row), round(col)], (200, 120, 0), tol=60)
    image = with_dot(picture, theta)
    col, row = dot_pixel(picture, theta)
    assert _is_colour(image[round(row), round(col)], DOT_COLOUR, tol=0)
    changed = np.argwhere(np.any(image != picture.image, axis=2))
    assert np.all(np.hypot(changed[:, 0] - row, changed[:, 1] - col) <= 7.0)  # only the dot (and its rim)
