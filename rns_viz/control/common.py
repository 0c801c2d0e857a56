"""What every control law shares: gains with units, the output record, the state of the coupling.

One call signature for every law: ``law(t, q, v) -> ControlOutput`` with q = (x_b, theta) and
v = (x_b', theta'); the law returns joint torques (N m) for the plant.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Protocol

import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.rns import damped_pinv, damped_row_inverse


class InvalidGain(ValueError):
    """A gain that is not a finite number in its allowed range."""


@dataclass(frozen=True)
class Gains:
    """Control gains, SI units. Matrices of the paper are these scalars times the identity."""

    g_b: float = 0.0  # 1/s: vibration suppression, G_b = g_b E in (15), (30); G_b = H_b g_b in (16)
    g_m: float = 0.0  # 1/s: joint damping G_m in (15)/(16), position gain g_m in (30)
    G_p: float = 400.0  # 1/s^2: end-effector position gain, Eq. (24)
    G_d: float = 200.0  # 1/s: end-effector velocity gain, Eq. (24)
    k_p: float = 400.0  # 1/s^2: joint reference tracking in the RNS (acceleration laws)
    k_d: float = 40.0  # 1/s: joint reference damping in the RNS (acceleration laws)
    servo_bandwidth: float = 300.0  # rad/s: joint velocity servo behind (30)

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value):
                raise InvalidGain(f"gain {f.name} must be a finite number, got {value!r}")
            if value < 0:
                raise InvalidGain(f"gain {f.name} must not be negative, got {value}")
            if value > 1e6:
                raise InvalidGain(f"gain {f.name} = {value} is beyond any stable setting (max 1e6)")
        if self.servo_bandwidth <= 0:
            raise InvalidGain("servo_bandwidth must be positive")


@dataclass
class ControlOutput:
    """Torques and what the law saw, for logs, plots and readouts."""

    tau: np.ndarray  # (n,) N m
    coupling_momentum: np.ndarray  # (r,) L = S H_bm theta', Eq. (8)
    sigma_hbm: float  # distance to singularity of S H_bm (its smallest singular value)
    sigma_jbar: float = math.nan  # distance to singularity of J-bar (tracking laws)
    theta_ref: np.ndarray | None = None  # (n,) rad
    ee_ref: np.ndarray | None = None  # (p,) m, base frame
    extra: dict[str, float] = field(default_factory=dict)


class ControlLaw(Protocol):
    """The one signature of every law."""

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput: ...


class Coupling:
    """The blocks of Eq. (1) at one state, restricted to the selected base rows S.

    Built at every control step, so it is a plain slotted class and P_RNS (an n x n matrix that
    most laws only apply to one vector) is formed on first use; :meth:`project` applies it
    without forming it.
    """

    __slots__ = (
        "H_b",
        "H_bm",
        "H_bm_pinv",
        "H_m",
        "M",
        "_P",
        "c",
        "coupling_momentum",
        "hbm_dot_thetadot",
        "row_pinv",
        "sigma",
        "theta",
        "thetadot",
        "x_b",
        "xdot_b",
    )

    def __init__(
        self,
        M: np.ndarray,
        c: np.ndarray,
        H_b: np.ndarray,
        H_bm: np.ndarray,
        H_m: np.ndarray,
        hbm_dot_thetadot: np.ndarray,
        H_bm_pinv: np.ndarray,
        sigma: float,
        q: np.ndarray,
        v: np.ndarray,
        m: int,
        rows: slice | np.ndarray,
        row_pinv: np.ndarray | None = None,
    ) -> None:
        self.M = M  # (m+n, m+n) joint-space inertia matrix
        self.c = c  # (m+n,) velocity terms (c_b, c_m)
        self.H_b = H_b  # (r, r) selected block
        self.H_bm = H_bm  # (r, n) S H_bm
        self.H_m = H_m  # (n, n)
        self.hbm_dot_thetadot = hbm_dot_thetadot  # (r,) S H_bm' theta'
        self.H_bm_pinv = H_bm_pinv  # (n, r), damped
        self.row_pinv = row_pinv  # (n,) the single column of H_bm_pinv when r = 1, else None
        self.sigma = sigma  # distance to singularity of S H_bm
        self.x_b = q[rows]  # (r,) selected base deflection, m
        self.xdot_b = v[rows]  # (r,)
        self.theta = q[m:]
        self.thetadot = v[m:]
        self.coupling_momentum = H_bm.dot(self.thetadot)  # (r,) L = S H_bm theta', Eq. (8)
        self._P: np.ndarray | None = None

    @property
    def P(self) -> np.ndarray:
        """(n, n) P_RNS = E - H_bm^+ H_bm, Eq. (9), with the damped inverse."""
        if self._P is None:
            self._P = np.eye(self.H_bm.shape[1]) - self.H_bm_pinv @ self.H_bm
        return self._P

    def project(self, u: np.ndarray) -> np.ndarray:
        """P_RNS u = u - H_bm^+ (H_bm u) without forming P_RNS."""
        if self.row_pinv is not None:
            return u - self.row_pinv * self.H_bm[0].dot(u)
        return u - self.H_bm_pinv @ (self.H_bm @ u)


class CouplingEvaluator:
    """Evaluates :class:`Coupling` with the model's own pinocchio data (one per law)."""

    def __init__(self, model: FsmsModel, singular_threshold: float | None = None) -> None:
        self.model = model
        self.rows = model.selected
        m = model.m
        # Index the selected rows with slices when S selects every base row (views, no copies).
        all_rows = len(self.rows) == m
        self._rows: slice | np.ndarray = slice(0, m) if all_rows else self.rows
        self._H_b_index = (slice(0, m), slice(0, m)) if all_rows else np.ix_(self.rows, self.rows)
        self._single_row = len(self.rows) == 1
        # Damping starts below 10 % of the coupling at the default configuration (kg m) and
        # reaches that same value at rank loss, so |H_bm^+| <= 1 / (2 lambda) = 5 / |H_bm(theta_0)|.
        q0 = model.q(model.spec.default_configuration)
        scale = float(np.linalg.norm(model.coupling_matrix(q0)))
        self.threshold = singular_threshold if singular_threshold is not None else 0.1 * max(scale, 1e-9)
        self.max_damping = self.threshold

    def __call__(self, q: np.ndarray, v: np.ndarray) -> Coupling:
        m, rows = self.model.m, self._rows
        M, c, hbm_dot = self.model.dynamics(q, v)
        H_bm = M[rows, m:]
        if self._single_row:  # closed form with floats (Sec. VII: TREP, the 3R)
            row_pinv, sigma, _ = damped_row_inverse(H_bm[0], self.threshold, self.max_damping)
            H_bm_pinv = row_pinv[:, None]
        else:
            row_pinv = None
            H_bm_pinv, sigma, _ = damped_pinv(H_bm, self.threshold, self.max_damping)
        return Coupling(M, c, M[self._H_b_index], H_bm, M[m:, m:], hbm_dot[rows], H_bm_pinv, sigma, q, v, m, rows, row_pinv)


def realize_acceleration(
    model: FsmsModel, cp: Coupling, q: np.ndarray, v: np.ndarray, thetaddot: np.ndarray
) -> np.ndarray:
    """Joint torques that produce ``thetaddot`` (resolved acceleration control, Fig. 1).

    The base acceleration is predicted from the base rows of Eq. (1) with the measured x_b and
    x_b' (no knowledge of external forces): H_b x_b'' = -K_b x_b - D_b x_b' - c_b - H_bm theta'';
    the arm rows of Eq. (1) then give tau = H_bm^T x_b'' + H_m theta'' + c_m + D_m theta'.
    """
    m, M, c = model.m, cp.M, cp.c
    if m == 1:  # scalars for a 1-DOF base
        h = M[0, 1:]
        rhs = -model.K_b[0, 0] * q[0] - model.D_b[0, 0] * v[0] - c[0] - h.dot(thetaddot)
        tau = h * (rhs / M[0, 0]) + cp.H_m.dot(thetaddot) + c[1:]
    else:
        rhs = -model.K_b @ q[:m] - model.D_b @ v[:m] - c[:m] - M[:m, m:] @ thetaddot
        tau = M[:m, m:].T @ np.linalg.solve(M[:m, :m], rhs) + cp.H_m @ thetaddot + c[m:]
    if model.has_joint_damping:
        tau += model.D_m @ v[m:]
    return tau


def suppression_acceleration(cp: Coupling, g_b: float) -> np.ndarray:
    """H_bm^+ (H_b G_b x_b' - H_bm' theta'): the vibration-suppression part of Eq. (15)."""
    return cp.H_bm_pinv @ (g_b * (cp.H_b @ cp.xdot_b) - cp.hbm_dot_thetadot)


def range_acceleration(cp: Coupling, g_b: float, g_m: float) -> np.ndarray:
    """H_bm^+ (H_b G_b x_b' - H_bm' theta' - G_m L): the part of theta'' in Eq. (15) outside the RNS.

    G_b = g_b E, G_m = g_m E. The -G_m L term is the law's -G_m (E - P) theta', because
    (E - P) theta' = H_bm^+ H_bm theta' = H_bm^+ L (Eqs. 8, 9), also with the damped inverse.
    """
    if cp.row_pinv is not None:  # one coupling row: a scalar times the inverse column
        y = g_b * cp.H_b[0, 0] * cp.xdot_b[0] - cp.hbm_dot_thetadot[0] - g_m * cp.coupling_momentum[0]
        return cp.row_pinv * y
    return cp.H_bm_pinv @ (g_b * (cp.H_b @ cp.xdot_b) - cp.hbm_dot_thetadot - g_m * cp.coupling_momentum)
