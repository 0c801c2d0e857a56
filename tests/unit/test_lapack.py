"""The per-step LAPACK calls (rns_viz.lapack) agree with numpy.linalg and fail as it does."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from rns_viz.lapack import singular_values, solve
from rns_viz.model import FsmsModel


def _boom7_blocks() -> tuple[np.ndarray, np.ndarray]:
    """boom7's H_b (6 x 6) and weighted S H_bm (6 x 7) at its default configuration: the step's matrices."""
    model = FsmsModel.from_name("boom7")
    M = model.mass_matrix(model.q(model.spec.default_configuration))
    return M[:6, :6].copy(), M[:6, 6:] * model.coupling_weights[:, None]


@pytest.mark.parametrize("rows", [1, 2, 3, 6])
def test_agrees_with_numpy_on_random_matrices(rows: int) -> None:
    rng = np.random.default_rng(rows)
    for _ in range(200):
        A = rng.normal(size=(rows, rows + 1)) * 10.0 ** rng.uniform(-3, 3)
        G = A @ A.T + 1e-3 * np.abs(A).max() ** 2 * np.eye(rows)  # conditioned like the damped G of rns
        b, B = rng.normal(size=rows), rng.normal(size=(rows, rows + 1))
        s = np.linalg.svd(A, compute_uv=False)
        np.testing.assert_allclose(singular_values(A), s, rtol=1e-13, atol=1e-14 * s[0])
        # LU with partial pivoting either way; two OpenBLAS builds may round one last bit apart
        np.testing.assert_allclose(solve(G, b), np.linalg.solve(G, b), rtol=1e-11)
        np.testing.assert_allclose(solve(G, B), np.linalg.solve(G, B), rtol=1e-11)


def test_boom7_blocks_solve_and_singular_values() -> None:
    H_b, WH_bm = _boom7_blocks()
    rhs = np.arange(1.0, 7.0)
    x = solve(H_b, rhs)
    np.testing.assert_allclose(H_b @ x, rhs, rtol=1e-12)
    s = singular_values(WH_bm)
    assert s.shape == (6,) and np.all(np.diff(s) <= 0)  # largest first
    np.testing.assert_allclose(s**2, np.linalg.eigvalsh(WH_bm @ WH_bm.T)[::-1], rtol=1e-10)


def test_failures_are_numpys() -> None:
    with pytest.raises(np.linalg.LinAlgError, match="Singular"):
        solve(np.array([[1.0, 2.0], [2.0, 4.0]]), np.ones(2))
    A = np.ones((3, 4))
    A[1, 2] = np.nan
    with pytest.raises(np.linalg.LinAlgError, match="did not converge"):
        np.linalg.svd(A, compute_uv=False)
    with pytest.raises(np.linalg.LinAlgError, match="did not converge"):
        singular_values(A)


def test_importing_the_simulation_does_not_import_scipy() -> None:
    """scipy is bound on the first solve, so `import rns_viz.sim` stays as quick as without it."""
    code = "import sys, rns_viz.sim, rns_viz.control; print('scipy.linalg' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
