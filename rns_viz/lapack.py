"""The dense solve and the singular values of every control step, by LAPACK called directly.

The per-step matrices are small (boom7: W S H_bm is 6 x 7, H_b 6 x 6), and on them numpy.linalg's
wrappers (argument checks, an error-state context per call) cost several times the routine itself.
These call the routines numpy.linalg calls (dgesv for ``solve``, dgesdd for ``svd(compute_uv=False)``)
through scipy's public LAPACK bindings, and fail the way numpy.linalg fails (``numpy.linalg.LinAlgError``).
scipy is imported on the first call, so that importing rns_viz costs no more than before.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

_routines: dict[str, Callable[..., Any]] = {}  # dgesv and dgesdd, bound on first use


def _bind() -> dict[str, Callable[..., Any]]:
    from scipy.linalg import lapack

    _routines.update(dgesv=lapack.dgesv, dgesdd=lapack.dgesdd)
    return _routines


def solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x of A x = b for a square float matrix A, b a vector or columns: ``np.linalg.solve`` for one system."""
    _, _, x, info = (_routines or _bind())["dgesv"](A, b)
    if info > 0:
        raise np.linalg.LinAlgError("Singular matrix")
    if info < 0:
        raise ValueError(f"LAPACK dgesv: argument {-info} is invalid")
    return x


def singular_values(A: np.ndarray) -> np.ndarray:
    """The singular values of a float matrix, largest first: ``np.linalg.svd(A, compute_uv=False)`` for one matrix."""
    _, s, _, info = (_routines or _bind())["dgesdd"](A, compute_uv=0)
    if info != 0:  # did not converge, or a NaN entry (which dgesdd reports as an invalid argument)
        raise np.linalg.LinAlgError("SVD did not converge")
    return s
