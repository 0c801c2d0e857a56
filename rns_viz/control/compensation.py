"""Dynamic redundancy (Sec. III-B): a task arm tracks, a compensating arm cancels its reaction.

For arms branching from the base (``[arms]`` of the parameter file), theta = (theta_1, theta_2) with
theta_1 the task arm's joints and theta_2 the compensator's, and S H_bm = [S H_bm,1, S H_bm,2].

- Task arm: ordinary resolved-acceleration tracking, no reactionless restriction,
      theta_1'' = J_1^+ (x_d'' + G_d e' + G_p e - J' theta'),  e = x_d - x_e.
- Compensating arm: the base rows of Eq. (1) with the paper's inversion (9)-(10) for theta_2,
      theta_2'' = H_bm,2^+ (S H_b G_b x_b' - S H_bm' theta' - G_m L - S H_bm,1 theta_1'') + P_2 u_2,
  L = S (H_bm,1 theta_1' + H_bm,2 theta_2') (Eq. 8), so that S H_bm theta'' + S H_bm' theta' = S H_b G_b x_b'
  - G_m L, Eq. (15)'s right-hand side (:func:`~rns_viz.control.acceleration.base_rows_demand`, S on the rows
  of H_b: every base velocity): with G_b = 0 the coupling momentum stays zero (Eq. 10 with L_0 = 0) and -G_m L
  removes any drift; G_b is vibration suppression (15) through the compensator alone (law (30) is
  the integral of the same term for velocity-commanded drives; not provided here).
  P_2 = E - H_bm,2^+ H_bm,2 (Eq. 9) and u_2 climbs ln(sigma_2^2 + eps^2) + limit barriers: the
  compensator's own null space keeps it off its singularities (sigma_2 = sigma_min(S H_bm,2) = 0)
  and joint limits.
- ``compensate=False``: the compensator is held (joint servo), for the shadow/comparison run.

Torques by resolved acceleration (:func:`~rns_viz.control.common.realize_acceleration`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from rns_viz.control.acceleration import base_rows_demand
from rns_viz.control.common import ControlOutput, CouplingEvaluator, Gains, LawKind, realize_acceleration
from rns_viz.control.null_input import TaskReference
from rns_viz.control.reference import ReferenceSample, TaskSample
from rns_viz.model import FsmsModel
from rns_viz.profiles import quintic
from rns_viz.rns import damped_pinv, singularity_distance, weighted_damped_pinv

LIMIT_MARGIN = math.radians(30.0)  # rad: the limit term of the avoidance measure acts this close to a limit
AVOID_EVERY_S = 0.01  # s between evaluations of the avoidance gradient (ten 1 ms steps; a slow null-space
# drift, its RNEA derivatives cost as much as the rest of the law); P_2 is applied to it at every call


@dataclass(frozen=True)
class TaskCircle:
    """x_d(t) on a circle of ``radius`` (m) about ``center`` in the task plane, started at angle ``phase``.

    The angle runs ``turns`` full turns with a quintic profile over ``duration`` from ``t0`` (rest to rest).
    """

    center: np.ndarray
    radius: float
    duration: float  # s
    t0: float = 0.0  # s
    turns: float = 1.0
    phase: float = 0.0  # rad

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, ds, dds = quintic((t - self.t0) / self.duration)
        span = 2.0 * math.pi * self.turns
        phi, dphi, ddphi = self.phase + span * s, span * ds / self.duration, span * dds / self.duration**2
        c, si = math.cos(phi), math.sin(phi)
        r = self.radius
        x = self.center + r * np.array([c, si])
        xdot = r * dphi * np.array([-si, c])
        xddot = r * ddphi * np.array([-si, c]) - r * dphi**2 * np.array([c, si])
        return x, xdot, xddot


class CompensatingLaw:
    """Task arm tracking + compensating arm by (9)-(10)/(15); see the module docstring.

    ``avoid_gain`` (rad/s^2 per unit gradient of the avoidance measure) and ``null_damping`` (1/s)
    shape u_2 = avoid_gain grad w - null_damping theta_2'. ``hold`` is theta_2 for ``compensate=False``.
    """

    kind: LawKind = "acceleration"

    def __init__(
        self,
        model: FsmsModel,
        gains: Gains,
        target: TaskReference,
        compensate: bool = True,
        suppress: bool = True,
        hold: np.ndarray | None = None,
        avoid_gain: float = 2.0,
        null_damping: float = 5.0,
        jacobian_threshold: float = 1e-2,
    ) -> None:
        if "task" not in model.arm_groups or "compensating" not in model.arm_groups:
            raise ValueError(f"{model.name}: the compensating law needs [arms] task and compensating joints")
        self.model = model
        self.gains = gains
        self.target = target
        self.compensate = compensate
        self.suppress = suppress
        self.avoid_gain, self.null_damping = avoid_gain, null_damping
        self.jacobian_threshold = jacobian_threshold
        self.task = model.arm_groups["task"].index
        self.comp = model.arm_groups["compensating"].index
        self.coupling = CouplingEvaluator(model)
        theta0 = model.spec.default_configuration
        self.hold = np.array(theta0[self.comp] if hold is None else hold, dtype=float)
        # Damping of H_bm,2^+ starts below 10 % of sigma_min(W S H_bm,2) at theta_0 (as CouplingEvaluator).
        self.weights = model.coupling_weights
        sigma0 = float(singularity_distance(self._comp_coupling(model.q(theta0)), self.weights))
        self.threshold = 0.1 * max(sigma0, 1e-9)
        m = model.m
        self._lower, self._upper = model.lower[self.comp], model.upper[self.comp]
        self._pm = pin.Model(model.pin_model)  # gravity-free copy: d(M a)/dq from RNEA derivatives
        self._pm.gravity.linear[:] = 0.0
        self._pd = self._pm.createData()
        self._zeros = np.zeros(model.nv)
        self._cols = m + self.comp  # compensator columns of M
        self._t = 0.0
        self._rehold = False
        self._grad: np.ndarray | None = None  # the avoidance gradient in use, and when it was taken (s)
        self._grad_t = math.nan

    # -- ControlLaw protocol ------------------------------------------------------------------
    def retune(self, gains: Gains) -> None:
        self.gains = gains

    def sampled(self, t: float) -> bool:
        """A digital controller while it suppresses through the compensator (g_b in force); held or only
        cancelling the reaction, a joint servo (see ControlLaw.sampled)."""
        return self.compensate and self.suppress and self.gains.g_b != 0.0

    def set_suppression(self, on: bool) -> None:
        """Switch the G_b term (vibration suppression through the compensator) on or off."""
        self.suppress = on

    def set_compensation(self, on: bool) -> None:
        """Compensate (True) or hold the compensator at its present angles (False)."""
        if on != self.compensate:
            self.compensate, self._rehold = on, not on

    def follow(self, sample: ReferenceSample) -> None:
        if not isinstance(sample, TaskSample):
            raise TypeError(f"the compensating law follows a task target, not a {type(sample).__name__}")
        self.target = sample

    # -- the law ----------------------------------------------------------------------------
    def _comp_coupling(self, q: np.ndarray) -> np.ndarray:
        return self.model.coupling_matrix(q)[:, self.comp]

    def task_acceleration(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
        """theta_1'' of resolved-acceleration tracking, sigma_min(J_1) and x_d."""
        model = self.model
        J, Jdot_thetadot, ee = model.ee_kinematics(q, v[model.m :])
        x_d, xdot_d, xddot_d = self.target(self._t)
        p = len(x_d)
        J1 = J[:p, self.task]
        e = x_d - ee[model.task_rows][:p]
        edot = xdot_d - J[:p] @ v[model.m :]
        inv = damped_pinv(J1, self.jacobian_threshold, self.jacobian_threshold)  # two rows: a closed form
        acc = inv.inverse @ (xddot_d + self.gains.G_d * edot + self.gains.G_p * e - Jdot_thetadot[:p])
        if J1.shape[1] > p:  # a redundant task arm: damp its self-motion (E - J_1^+ J_1)
            w = v[model.m + self.task]
            acc -= self.null_damping * (w - inv.inverse @ (J1 @ w))
        return acc, inv.sigma_min, x_d

    def avoidance_gradient(self, q: np.ndarray, H2: np.ndarray) -> np.ndarray:
        """grad over theta_2 of w = ln det(A A^T + eps^2 E) - sum (1 - d/delta)_+^2, 1/rad, A = W H2 (rows in kg m).

        d: distance of a joint to each of its limits; delta = LIMIT_MARGIN, so the limits act only near them.

        d/dtheta_k ln det(A A^T + eps^2) = 2 sum_ij W_ij dA_ij/dtheta_k with W = (A A^T + eps^2)^-1 A;
        sum_j W_ij dA_ij/dtheta = d(M a_i)/dq row i with a_i = W_i on the compensator columns, held:
        pinocchio's RNEA derivatives at v = 0 and a = a_i (gravity-free copy of the model).
        """
        rows = self.model.selected
        r = H2.shape[0]
        weights = np.ones(r) if self.weights is None else self.weights
        H2 = H2 * weights[:, None]
        if r == 1:  # one base row: W = h / (|h|^2 + eps^2) without a solve
            W = H2 / (float(H2[0].dot(H2[0])) + self.threshold**2)
        else:
            W = np.linalg.solve(H2 @ H2.T + self.threshold**2 * np.eye(r), H2)
        W = W * weights[:, None]  # d(W H2)_ij = w_i dH2_ij: the weights once more on the rows of M's derivative
        grad = np.zeros(len(self.comp))
        a = self._zeros.copy()
        for i in range(r):
            a[:] = 0.0
            a[self._cols] = W[i]
            dtau_dq = pin.computeRNEADerivatives(self._pm, self._pd, q, self._zeros, a)[0]
            grad += 2.0 * dtau_dq[rows[i], self._cols]
        theta2 = q[self._cols]
        near_lo = np.maximum(0.0, 1.0 - (theta2 - self._lower) / LIMIT_MARGIN)
        near_hi = np.maximum(0.0, 1.0 - (self._upper - theta2) / LIMIT_MARGIN)
        return grad + 2.0 / LIMIT_MARGIN * (near_lo - near_hi)

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput:
        self._t = t
        model, g, m = self.model, self.gains, self.model.m
        cp = self.coupling(q, v)
        acc1, sigma_j, x_d = self.task_acceleration(q, v)
        H1, H2 = cp.H_bm[:, self.task], cp.H_bm[:, self.comp]
        inv2 = weighted_damped_pinv(H2, self.weights, self.threshold, self.threshold)
        thetadot2 = v[self._cols]
        if self.compensate:
            g_b = g.g_b if self.suppress else 0.0
            y = base_rows_demand(cp, g_b, g.g_m) - H1 @ acc1  # Eq. (15)'s, less what the task arm takes
            if self._grad is None or not 0.0 <= t - self._grad_t < AVOID_EVERY_S - 1e-9:  # 1e-9 s: summed steps
                self._grad, self._grad_t = self.avoidance_gradient(q, H2), t
            u2 = self.avoid_gain * self._grad - self.null_damping * thetadot2
            acc2 = inv2.inverse @ y + u2 - inv2.inverse @ (H2 @ u2)  # H_bm,2^+ y + P_2 u_2, Eqs. (9), (15)
        else:
            if self._rehold:
                self.hold, self._rehold = q[self._cols].copy(), False
            acc2 = g.k_p * (self.hold - q[self._cols]) - g.k_d * thetadot2
        thetaddot = np.empty(model.n)
        thetaddot[self.task], thetaddot[self.comp] = acc1, acc2
        L_task = H1 @ v[m + self.task]
        return ControlOutput(
            tau=realize_acceleration(model, cp, q, v, thetaddot),
            coupling_momentum=cp.coupling_momentum,
            sigma_hbm=inv2.sigma_min,
            sigma_jbar=sigma_j,
            ee_ref=x_d,
            extra={"L_task": float(np.linalg.norm(L_task)), "sigma_hbm_total": cp.sigma},
        )
