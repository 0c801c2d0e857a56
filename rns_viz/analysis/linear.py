"""The closed loop of plant + law, linearised about an equilibrium, as a function of the gains.

Equilibrium: joint angles theta at rest, x_b = 0, v = 0, the law holding theta (law (30) with the
fixed reference theta, Sec. VII-D-1; laws (15)/(16) with the default null input u = -G_m theta',
Fig. 3). Both the law and the plant's response are affine in (g_b, g_m) for a fixed servo
bandwidth: theta'' of (15) and the velocity command of (30) are, the torque of resolved acceleration
is linear in theta'', and the plant's acceleration is affine in the torque. Hence

    A(g_b, g_m) = A0 + g_b A_b + g_m A_m,

with A0, A_b, A_m from three central-difference linearisations at (0, 0), (1, 0), (0, 1) 1/s.

Two views of the same loop (``discrete``):
- discrete (default): A is the Jacobian of the simulator's step map x_k -> x_{k+1}, torque computed
  once and held over the RK4 step of dt (a digital controller, rns_viz.sim); its eigenvalues mu are
  reported as continuous-equivalent rates lambda = log(mu) / dt (1/s), so zero-order-hold effects
  of high gains are included;
- continuous: A is the Jacobian of x' = f(x), the law evaluated continuously.

Neutral coordinates: under (15)/(16) no term feeds the joint angles back (any theta at rest is an
equilibrium), so their columns of A vanish at every gain (identity columns for the step map); they
add n eigenvalues 0 (mu = 1) and are dropped from the analysed matrices (``kept``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from rns_viz.analysis.kick import Kick, default_kick
from rns_viz.control import AccelerationLaw, FixedReference, Gains, LawKind, TorqueLaw, VelocityLaw
from rns_viz.control.common import ControlLaw
from rns_viz.model import FsmsModel
from rns_viz.sim.plant import Plant

LAW_NAMES: dict[str, LawKind] = {
    "15": "acceleration",
    "16": "torque",
    "30": "velocity",
    "acceleration": "acceleration",
    "torque": "torque",
    "velocity": "velocity",
}
EQUATIONS: dict[LawKind, str] = {"acceleration": "(15)", "torque": "(16)", "velocity": "(30)"}
StateView = Literal["discrete", "continuous"]
FD_STEP = 1e-6  # central-difference step on every state coordinate (m, rad, m/s, rad/s)
FORCE_STEP = 1e-3  # N (N m): central-difference step on the base force


def law_kind(name: str) -> LawKind:
    """'15', '16', '30' or a kind name -> the law's kind; ValueError for anything else."""
    try:
        return LAW_NAMES[str(name).strip().lower()]
    except KeyError:
        raise ValueError(f"unknown law {name!r}: choose 15, 16, 30, acceleration, torque or velocity") from None


def build_law(model: FsmsModel, kind: LawKind, theta: np.ndarray, gains: Gains) -> ControlLaw:
    """The law the simulator runs, holding ``theta`` (rad) at rest."""
    if kind == "velocity":
        return VelocityLaw(model, gains, FixedReference(np.array(theta, dtype=float)))
    if kind == "acceleration":
        return AccelerationLaw(model, gains)
    if kind == "torque":
        return TorqueLaw(model, gains)
    raise ValueError(f"no linearisation for a {kind!r} law")


def _with(gains: Gains, g_b: float, g_m: float) -> Gains:
    return replace(gains, g_b=g_b, g_m=g_m)


@dataclass(frozen=True)
class LinearLoop:
    """A(g_b, g_m) = A0 + g_b A_b + g_m A_m on the state (x_b, theta, x_b', theta'), restricted to ``kept``.

    ``view`` says whether A is a step map (``dt`` s) or a continuous state matrix; :meth:`rates`
    converts eigenvalues to 1/s either way.
    """

    model_name: str
    law: LawKind
    theta: np.ndarray  # (n,) rad: the equilibrium
    view: StateView
    dt: float  # s (the step map's period; also kept for the continuous view)
    servo_bandwidth: float  # rad/s (law (30) only)
    A0: np.ndarray  # (d, d) at g_b = g_m = 0
    A_b: np.ndarray  # (d, d) per 1/s of g_b
    A_m: np.ndarray  # (d, d) per 1/s of g_m
    kept: np.ndarray  # (d,) indices into the full state of length 2 (m + n)
    m: int  # base coordinates
    nv: int  # m + n
    M: np.ndarray  # (nv, nv) inertia matrix of Eq. (1) at the equilibrium
    basis: np.ndarray  # (d, d) orthonormal: its last ``seen`` columns span the modes x_b can show
    seen: int  # dimension of the observable part (x_b) of A(g_b, g_m), the same at every gain
    force_input: np.ndarray  # (d, m): state change per N of base force held over a step (continuous: rate per N)
    coupling: np.ndarray  # (r, n) S H_bm at the equilibrium, kg m (kg m^2 on a rotation)
    joint_margins: tuple[np.ndarray, np.ndarray]  # (n,) each: rad the joints may turn down / up to their limits
    kick: Kick  # the kick whose response the modes are grouped by (the model's default kick)
    base_names: tuple[str, ...]  # the base coordinates ("x", "y", ..., "rz")

    def matrix(self, g_b: float | np.ndarray, g_m: float | np.ndarray) -> np.ndarray:
        """A at the given gains (1/s); arrays of gains broadcast to (..., d, d)."""
        gb = np.asarray(g_b, dtype=float)[..., None, None]
        gm = np.asarray(g_m, dtype=float)[..., None, None]
        return self.A0 + gb * self.A_b + gm * self.A_m

    def rates(self, eigenvalues: np.ndarray) -> np.ndarray:
        """Continuous-equivalent eigenvalues lambda (1/s): log(mu) / dt for the step map."""
        if self.view == "continuous":
            return eigenvalues
        with np.errstate(divide="ignore"):
            return np.log(eigenvalues.astype(complex)) / self.dt

    def poles(self, g_b: float | np.ndarray, g_m: float | np.ndarray) -> np.ndarray:
        """Closed-loop poles lambda (1/s), (..., d), for gains that broadcast together."""
        return self.rates(np.linalg.eigvals(self.matrix(g_b, g_m)))

    @property
    def regime(self) -> str:
        """Where the map's predictions hold, in words: the kick and the rest configuration."""
        theta = ", ".join(f"{a:.0f}" for a in np.rad2deg(self.theta))
        return f"after {self.kick.words(self.base_names)}, arm at rest at θ = ({theta})°"

    @property
    def swing_map(self) -> np.ndarray:
        """(n, r): (S H_bm)^+, the joint motion outside the RNS that makes a coupling momentum integral."""
        return np.linalg.pinv(self.coupling)

    @property
    def joint_rates(self) -> np.ndarray:
        """(n, d): picks theta' from the kept states."""
        return np.eye(len(self.kept))[np.searchsorted(self.kept, self.nv + np.arange(self.m, self.nv))]

    @property
    def neutral(self) -> int:
        """How many coordinates were dropped as neutral (the arm's n angles under (15)/(16))."""
        return 2 * self.nv - len(self.kept)


class ClosedLoop:
    """The closed-loop right-hand side (or step map) of plant + law at given gains, state x = (q, v)."""

    def __init__(self, model: FsmsModel, kind: LawKind, theta: np.ndarray, gains: Gains, dt: float = 1e-3) -> None:
        self.model, self.dt = model, dt
        self.plant = Plant(model)
        self.law = build_law(model, kind, theta, gains)
        self.x0 = np.concatenate((model.q(theta), np.zeros(model.nv)))

    def retune(self, gains: Gains) -> None:
        self.law.retune(gains)

    def rhs(self, x: np.ndarray) -> np.ndarray:
        """x' = (v, q'') with the law evaluated at x (continuous time)."""
        nv = self.model.nv
        q, v = x[:nv], x[nv:]
        tau = self.law(0.0, q, v).tau
        return np.concatenate((v, self.plant.acceleration(q, v, tau, None)))

    def step(self, x: np.ndarray, force: np.ndarray | None = None) -> np.ndarray:
        """x_{k+1}: the torque at x held over one RK4 step of dt, as in :class:`~rns_viz.sim.Simulator`,
        with a base force (N) held over the step."""
        nv = self.model.nv
        tau = self.law(0.0, x[:nv], x[nv:]).tau
        return self.plant.rk4_state_step(x, tau, force, self.dt)

    def force_jacobian(self) -> np.ndarray:
        """(2 nv, m): d x_{k+1} / d f (per N) at the equilibrium for a force held over the step, by central
        differences (the law sees only x_k, so this does not depend on the gains)."""
        x0, h = self.x0, FORCE_STEP
        return np.column_stack([(self.step(x0, h * e) - self.step(x0, -h * e)) / (2 * h) for e in np.eye(self.model.m)])

    def jacobian(self, view: StateView) -> np.ndarray:
        """Central-difference Jacobian of :meth:`step` or :meth:`rhs` at the equilibrium."""
        f = self.step if view == "discrete" else self.rhs
        x0, d = self.x0, len(self.x0)
        J = np.empty((d, d))
        for j in range(d):
            e = np.zeros(d)
            e[j] = FD_STEP
            J[:, j] = (f(x0 + e) - f(x0 - e)) / (2.0 * FD_STEP)
        return J


def linearise(
    model: FsmsModel,
    law: LawKind | str,
    theta: np.ndarray | None = None,
    *,
    view: StateView = "discrete",
    dt: float = 1e-3,
    gains: Gains | None = None,
    kick: Kick | None = None,
) -> LinearLoop:
    """Linearise plant + law about theta at rest (default: the model's default configuration).

    ``gains`` supplies the gains other than g_b and g_m (the servo bandwidth of (30), 300 rad/s by
    default); g_b and g_m are the map's axes. ``kick`` (default: the model's, :func:`default_kick`)
    is the push whose response the modes are read from.
    """
    kind = law_kind(law)
    if view not in ("discrete", "continuous"):
        raise ValueError(f"view must be 'discrete' or 'continuous', got {view!r}")
    theta = np.array(model.spec.default_configuration if theta is None else theta, dtype=float)
    if theta.shape != (model.n,) or not np.all(np.isfinite(theta)):
        raise ValueError(f"theta must be {model.n} finite joint angles (rad)")
    base = gains or Gains()
    loop = ClosedLoop(model, kind, theta, _with(base, 0.0, 0.0), dt)
    drift = float(np.abs(loop.rhs(loop.x0)).max())
    if not drift < 1e-9:  # e.g. gravity along a base axis loads the spring: x_b = 0 is no equilibrium
        raise ValueError(f"{model.name}: theta at rest with x_b = 0 is not an equilibrium (|x'| = {drift:.3g})")
    A0 = loop.jacobian(view)
    force = loop.force_jacobian() if view == "discrete" else None
    loop.retune(_with(base, 1.0, 0.0))
    A_b = loop.jacobian(view) - A0
    loop.retune(_with(base, 0.0, 1.0))
    A_m = loop.jacobian(view) - A0
    kept = _non_neutral(A0, A_b, A_m, model, view)
    sub = np.ix_(kept, kept)
    A0, A_b, A_m = A0[sub], A_b[sub], A_m[sub]
    M = model.mass_matrix(loop.x0[: model.nv]).copy()
    force_input = _impulse_input(M, model.m, kept) if force is None else force[kept]
    kick = kick or default_kick(model)
    if len(kick.direction) != model.m:
        raise ValueError(
            f"{model.name}'s base has {model.m} coordinates; the kick's direction gives {len(kick.direction)}"
        )
    shifted = A0 - np.eye(len(kept)) if view == "discrete" else A0  # same invariant subspaces
    C = np.eye(2 * model.nv)[: model.m][:, kept]  # x_b
    basis, seen = _observable_basis((shifted, A_b, A_m), C)
    return LinearLoop(
        model_name=model.name,
        law=kind,
        theta=theta,
        view=view,
        dt=dt,
        servo_bandwidth=base.servo_bandwidth,
        A0=A0,
        A_b=A_b,
        A_m=A_m,
        kept=kept,
        m=model.m,
        nv=model.nv,
        M=M,
        basis=basis,
        seen=seen,
        force_input=force_input,
        coupling=model.coupling_matrix(loop.x0[: model.nv]).copy(),
        joint_margins=(theta - model.lower, model.upper - theta),
        kick=kick,
        base_names=tuple(j.removeprefix("base_") for j in model.spec.base.joints),
    )


def _non_neutral(A0: np.ndarray, A_b: np.ndarray, A_m: np.ndarray, model: FsmsModel, view: StateView) -> np.ndarray:
    """State indices to keep: all but the joint angles when no gain feeds them back."""
    d = len(A0)
    angles = np.arange(model.m, model.nv)
    identity = np.eye(d)[:, angles] if view == "discrete" else 0.0
    scale = max(np.abs(A0).max(), 1.0)
    feedback = max(np.abs(A0[:, angles] - identity).max(), np.abs(A_b[:, angles]).max(), np.abs(A_m[:, angles]).max())
    if feedback > 1e-8 * scale:
        return np.arange(d)
    return np.setdiff1d(np.arange(d), angles)


def _impulse_input(M: np.ndarray, m: int, kept: np.ndarray) -> np.ndarray:
    nv = len(M)
    B = np.zeros((2 * nv, m))
    B[nv:, :] = np.linalg.solve(M, np.eye(nv)[:, :m])
    return B[kept]


def _observable_basis(mats: tuple[np.ndarray, ...], C: np.ndarray, tol: float = 1e-7) -> tuple[np.ndarray, int]:
    """Orthonormal basis [N, O]: O spans the smallest subspace holding C^T and invariant under every
    A^T of ``mats``, so N (its complement: motions x_b never shows, e.g. the arm's motion in the RNS)
    is invariant under A(g_b, g_m) at all gains, and in this basis A is block upper triangular with
    the modes x_b can show in the lower-right block of size dim O.
    """
    scaled = [A.T / max(np.abs(A).max(), 1e-300) for A in mats]
    Q = np.linalg.svd(C.T, full_matrices=False)[0]
    while True:
        U, s, _ = np.linalg.svd(np.hstack([Q, *(A @ Q for A in scaled)]), full_matrices=False)
        r = int(np.sum(s > tol * s[0]))
        if r == Q.shape[1]:
            break
        Q = U[:, :r]
    full = np.linalg.svd(Q, full_matrices=True)[0]  # first r columns span Q, the rest its complement
    return np.hstack([full[:, r:], Q]), r
