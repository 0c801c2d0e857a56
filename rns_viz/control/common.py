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
from rns_viz.rns import damped_pinv


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


@dataclass
class Coupling:
    """The blocks of Eq. (1) at one state, restricted to the selected base rows S."""

    M: np.ndarray
    c: np.ndarray
    H_b: np.ndarray  # (r, r) selected block
    H_bm: np.ndarray  # (r, n) S H_bm
    H_m: np.ndarray
    hbm_dot_thetadot: np.ndarray  # (r,)
    H_bm_pinv: np.ndarray  # (n, r), damped
    P: np.ndarray  # (n, n) E - H_bm^+ H_bm
    sigma: float
    x_b: np.ndarray  # (r,) selected base deflection, m
    xdot_b: np.ndarray  # (r,)
    theta: np.ndarray
    thetadot: np.ndarray


class CouplingEvaluator:
    """Evaluates :class:`Coupling` with the model's own pinocchio data (one per law)."""

    def __init__(self, model: FsmsModel, singular_threshold: float | None = None) -> None:
        self.model = model
        self.rows = model.selected
        # Damping starts below 10 % of the coupling at the default configuration (kg m) and
        # reaches that same value at rank loss, so |H_bm^+| <= 1 / (2 lambda) = 5 / |H_bm(theta_0)|.
        q0 = model.q(model.spec.default_configuration)
        scale = float(np.linalg.norm(model.coupling_matrix(q0)))
        self.threshold = singular_threshold if singular_threshold is not None else 0.1 * max(scale, 1e-9)
        self.max_damping = self.threshold
        self.eye = np.eye(model.n)

    def __call__(self, q: np.ndarray, v: np.ndarray) -> Coupling:
        model, m, rows = self.model, self.model.m, self.rows
        M, c, hbm_dot = model.dynamics(q, v)
        H_bm = M[rows, m:]
        inv = damped_pinv(H_bm, self.threshold, self.max_damping)
        return Coupling(
            M=M,
            c=c,
            H_b=M[np.ix_(rows, rows)],
            H_bm=H_bm,
            H_m=M[m:, m:],
            hbm_dot_thetadot=hbm_dot[rows],
            H_bm_pinv=inv.inverse,
            P=self.eye - inv.inverse @ H_bm,
            sigma=inv.sigma_min,
            x_b=q[rows],
            xdot_b=v[rows],
            theta=q[m:],
            thetadot=v[m:],
        )


def realize_acceleration(
    model: FsmsModel, cp: Coupling, q: np.ndarray, v: np.ndarray, thetaddot: np.ndarray
) -> np.ndarray:
    """Joint torques that produce ``thetaddot`` (resolved acceleration control, Fig. 1).

    The base acceleration is predicted from the base rows of Eq. (1) with the measured x_b and
    x_b' (no knowledge of external forces): H_b x_b'' = -K_b x_b - D_b x_b' - c_b - H_bm theta''.
    """
    m = model.m
    H_b_full = cp.M[:m, :m]
    H_bm_full = cp.M[:m, m:]
    rhs = -model.K_b @ q[:m] - model.D_b @ v[:m] - cp.c[:m] - H_bm_full @ thetaddot
    xddot_b = rhs / H_b_full[0, 0] if m == 1 else np.linalg.solve(H_b_full, rhs)
    return H_bm_full.T @ xddot_b + cp.H_m @ thetaddot + cp.c[m:] + model.D_m @ v[m:]


def suppression_acceleration(cp: Coupling, g_b: float) -> np.ndarray:
    """H_bm^+ (H_b G_b x_b' - H_bm' theta'): the vibration-suppression part of Eq. (15)."""
    return cp.H_bm_pinv @ (g_b * (cp.H_b @ cp.xdot_b) - cp.hbm_dot_thetadot)
