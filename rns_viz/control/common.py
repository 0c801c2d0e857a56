"""What every control law shares: gains with units, the output record, the state of the coupling.

One call signature for every law: ``law(t, q, v) -> ControlOutput`` with q = (x_b, theta) and
v = (x_b', theta'); the law returns joint torques (N m) for the plant.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Literal, NamedTuple, Protocol

import numpy as np

from rns_viz.lapack import solve
from rns_viz.model import FsmsModel
from rns_viz.out_of_range import OutOfRange, check_range

if TYPE_CHECKING:
    from rns_viz.control.reference import ReferenceSample
from rns_viz.rns import (
    DampedInverse,
    damped_row_pinv,
    project_onto_rns,
    rns_projector,
    singularity_distance,
    weighted_damped_pinv,
)

LawKind = Literal["acceleration", "torque", "velocity", "servo"]


MAX_GAIN = 1e6  # any gain, in its units: far beyond every stable setting of the bundled models
GAIN_UNITS = {
    "g_b": "1/s",
    "g_m": "1/s",
    "G_p": "1/s²",
    "G_d": "1/s",
    "k_p": "1/s²",
    "k_d": "1/s",
    "servo_bandwidth": "rad/s",
}


class InvalidGain(ValueError):
    """A gain that is not a finite number in its allowed range."""


class GainOutOfRange(InvalidGain, OutOfRange):
    """A gain that is a number, but not a finite one from 0 to MAX_GAIN (its range and unit attached)."""


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
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise InvalidGain(f"gain {f.name} must be a number, got {value!r}")
            # (larger than MAX_GAIN is beyond any stable setting)
            check_range(f"gain {f.name}", value, 0.0, MAX_GAIN, GAIN_UNITS[f.name], error=GainOutOfRange)
        if self.servo_bandwidth <= 0:
            raise InvalidGain("servo_bandwidth must be positive")


@dataclass
class ControlOutput:
    """Torques and what the law saw, for logs, plots and readouts."""

    tau: np.ndarray  # (n,) N m
    coupling_momentum: np.ndarray  # (r,) L = S H_bm theta', Eq. (8)
    sigma_hbm: float  # distance to singularity of S H_bm, kg m: sigma_min(W S H_bm) (rns.singularity_distance)
    sigma_jbar: float = math.nan  # distance to singularity of J-bar (tracking laws)
    theta_ref: np.ndarray | None = None  # (n,) rad
    ee_ref: np.ndarray | None = None  # (p,) m, base frame
    extra: dict[str, float] | None = None  # a law's own extra outputs (None: none)


class ControlLaw(Protocol):
    """The one signature of every law, and what a live loop may change between two steps."""

    gains: Gains

    @property
    def kind(self) -> LawKind: ...

    @property
    def suppress(self) -> bool: ...

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> ControlOutput: ...

    def sampled(self, t: float) -> bool:
        """How the simulator applies this law over the step that starts at t.

        True: a digital controller, its torque computed at t and held over the step (vibration
        suppression, g_b in force). False: a joint servo on the measured state, evaluated wherever
        the integrator evaluates the plant (every RK4 stage, its state and time): a held arm then stays
        held and the base rings as the structure alone, not fed back by a torque half a step late.
        """
        ...

    def retune(self, gains: Gains) -> None:
        """New gains (and the null-space input's), from the next step on."""
        ...

    def set_suppression(self, on: bool) -> None:
        """Switch vibration suppression (the g_b term) on or off."""
        ...

    def follow(self, sample: ReferenceSample) -> None:
        """Track this reference sample from the next step on (TypeError if the law tracks no such thing)."""
        ...


class CouplingRow(NamedTuple):
    """The coupling of a 1-DOF base (one row) in Python floats, read by the one-row branches of
    Eq. (15) and Fig. 1: for a few joints, numbers cost less than numpy calls on tiny arrays."""

    H_b: float  # the base inertia (1 x 1)
    xdot_b: float  # the base velocity, m/s
    hbm_dot_thetadot: float  # S H_bm' theta'
    L: float  # S H_bm theta', Eq. (8)
    h: list[float]  # (n,) S H_bm
    thetadot: list[float]  # (n,) rad/s
    M_rows: list[list[float]]  # the inertia matrix of Eq. (1), row by row


class Coupling:
    """The blocks of Eq. (1) at one state, restricted to the selected base rows S.

    Built at every control step, so it is a plain slotted class that stores what every law uses
    and forms the rest on access: P_RNS (an n x n matrix usually applied to one vector, see
    :meth:`project`), H_b, x_b, x_b', H_bm' theta' and theta.
    """

    __slots__ = (
        "H_bm",
        "M",
        "_H_b_index",
        "_P",
        "_hbm_dot",
        "_m",
        "_q",
        "_rows",
        "_v",
        "c",
        "coupling_momentum",
        "inverse",
        "row",
        "sigma",
        "thetadot",
    )

    def __init__(
        self,
        M: np.ndarray,
        c: np.ndarray,
        hbm_dot_thetadot: np.ndarray,
        H_bm: np.ndarray,
        inverse: DampedInverse,
        q: np.ndarray,
        v: np.ndarray,
        rows: slice | np.ndarray,
        H_b_index: tuple,
    ) -> None:
        m = len(q) - H_bm.shape[1]
        self.M = M  # (m+n, m+n) joint-space inertia matrix of Eq. (1)
        self.c = c  # (m+n,) velocity terms (c_b, c_m)
        self.H_bm = H_bm  # (r, n) S H_bm
        self.thetadot = v[m:]
        self.coupling_momentum = H_bm.dot(self.thetadot)  # (r,) L = S H_bm theta', Eq. (8)
        self.row: CouplingRow | None = None  # the same coupling in Python floats (r = 1, CouplingEvaluator)
        self.inverse = inverse  # the damped H_bm^+ (rns.damped_pinv)
        self.sigma = inverse.sigma_min  # sigma_min(W S H_bm), kg m: the distance to singularity
        self._m, self._rows, self._H_b_index = m, rows, H_b_index
        self._q, self._v, self._hbm_dot = q, v, hbm_dot_thetadot  # (m+n,), (m+n,), (m,)
        self._P: np.ndarray | None = None

    @property
    def H_bm_pinv(self) -> np.ndarray:
        """(n, r) the damped H_bm^+."""
        return self.inverse.inverse

    @property
    def H_m(self) -> np.ndarray:
        """(n, n) arm block of the inertia matrix."""
        return self.M[self._m :, self._m :]

    @property
    def H_b(self) -> np.ndarray:
        """(r, r) selected block of the base inertia."""
        return self.M[self._H_b_index]

    @property
    def H_b_rows(self) -> np.ndarray:
        """(r, m) S H_b: the selected rows of the base inertia, every column (kg, kg m, kg m^2)."""
        return self.M[self._rows, : self._m]

    @property
    def base_momentum(self) -> np.ndarray:
        """(r,) S H_b x_b': the selected rows of H_b times all m base velocities (kg m/s, kg m^2/s).

        S selects rows only (Sec. III-B): the free components' velocities enter through H_b's
        off-diagonal block, which S H_b S^T x_b' would drop (documentation: models, boom7 in the app)."""
        return self.M[self._rows, : self._m].dot(self._v[: self._m])

    @property
    def hbm_dot_thetadot(self) -> np.ndarray:
        """(r,) S H_bm' theta'."""
        return self._hbm_dot[self._rows]

    @property
    def x_b(self) -> np.ndarray:
        """(r,) selected base deflection, m."""
        return self._q[self._rows]

    @property
    def xdot_b(self) -> np.ndarray:
        """(r,) selected base velocity, m/s."""
        return self._v[self._rows]

    @property
    def theta(self) -> np.ndarray:
        """(n,) joint angles, rad."""
        return self._q[self._m :]

    @property
    def P(self) -> np.ndarray:
        """(n, n) P_RNS of Eq. (9) with the damped inverse (:func:`rns_viz.rns.rns_projector`)."""
        if self._P is None:
            self._P = rns_projector(self.H_bm, self.H_bm_pinv)
        return self._P

    def project(self, u: np.ndarray) -> np.ndarray:
        """P_RNS u without forming P_RNS (:func:`rns_viz.rns.project_onto_rns`)."""
        return project_onto_rns(u, self.H_bm, self.H_bm_pinv)


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
        # Damping starts below 10 % of the distance to singularity sigma_min(W S H_bm) at the default
        # configuration (kg m: moment rows divided by the arm's length, rns.singularity_distance; |h| for
        # one row) and reaches that same value at rank loss, so |W H_bm^+| <= 10 / sigma_min(theta_0)
        # (sigma / (sigma^2 + lambda^2) peaks just below that). The damping acts on W S H_bm too, so its
        # onset and size are in one unit for every row (boom7: sigma_min 0.033 kg m, |W S H_bm| 3.1).
        self.weights = model.coupling_weights
        q0 = model.q(model.spec.default_configuration)
        scale = float(singularity_distance(model.coupling_matrix(q0), self.weights))
        self.threshold = singular_threshold if singular_threshold is not None else 0.1 * max(scale, 1e-9)
        self.max_damping = self.threshold
        # A 1-DOF base's one row in Python floats. Not one selected row of a larger base: S acts on the
        # rows of H_b, so S H_b x_b' needs every base velocity, not the selected diagonal entry.
        self._row = 0 if m == 1 and self.weights is None else None

    def __call__(self, q: np.ndarray, v: np.ndarray) -> Coupling:
        M, c, hbm_dot = self.model.dynamics(q, v)
        if self._row is not None:
            return self._one_row(M, c, hbm_dot, q, v, self._row)
        H_bm = M[self._rows, self.model.m :]
        inverse = weighted_damped_pinv(H_bm, self.weights, self.threshold, self.max_damping)
        return Coupling(M, c, hbm_dot, H_bm, inverse, q, v, self._rows, self._H_b_index)

    def _one_row(
        self, M: np.ndarray, c: np.ndarray, hbm_dot: np.ndarray, q: np.ndarray, v: np.ndarray, i: int
    ) -> Coupling:
        """The coupling of one selected base row i, its numbers taken once as Python floats (:class:`CouplingRow`).

        Per step on a 1-DOF base: the slots of :class:`Coupling` are filled directly (what its
        ``__init__`` computes with numpy on the one-row matrix comes here from the floats)."""
        m = self.model.m
        M_rows, v_values = M.tolist(), v.tolist()
        h, thetadot = M_rows[i][m:], v_values[m:]
        L = sum(map(operator.mul, h, thetadot))
        inverse = damped_row_pinv(h, self.threshold, self.max_damping)
        cp = Coupling.__new__(Coupling)
        cp.M, cp.c, cp.H_bm, cp.thetadot = M, c, M[i : i + 1, m:], v[m:]
        cp.coupling_momentum, cp.inverse, cp.sigma = np.array((L,)), inverse, inverse.sigma_min
        cp.row = CouplingRow._make((M_rows[i][i], v_values[i], hbm_dot.item(i), L, h, thetadot, M_rows))
        cp._m, cp._rows, cp._H_b_index = m, self._rows, self._H_b_index
        cp._q, cp._v, cp._hbm_dot, cp._P = q, v, hbm_dot, None
        return cp


def realize_acceleration(
    model: FsmsModel, cp: Coupling, q: np.ndarray, v: np.ndarray, thetaddot: np.ndarray
) -> np.ndarray:
    """Joint torques that produce ``thetaddot`` (resolved acceleration control, Fig. 1).

    The base acceleration is predicted from the base rows of Eq. (1) with the measured x_b and
    x_b' (no knowledge of external forces): H_b x_b'' = -K_b x_b - D_b x_b' - c_b - H_bm theta'';
    the arm rows of Eq. (1) then give tau = H_bm^T x_b'' + H_m theta'' + c_m + D_m theta'.
    """
    if model.m == 1:
        return _one_dof_base_torques(model, cp, q, v, thetaddot)
    return _any_base_torques(model, cp, q, v, thetaddot)


def _any_base_torques(
    model: FsmsModel, cp: Coupling, q: np.ndarray, v: np.ndarray, thetaddot: np.ndarray
) -> np.ndarray:
    """:func:`realize_acceleration` for an m-DOF base, as written there, with z = M (0, theta'') + c formed
    once: its base rows are c_b + H_bm theta'', its arm rows H_m theta'' + c_m (fewer numpy calls)."""
    m, M = model.m, cp.M
    z = M[:, m:].dot(thetaddot) + cp.c
    rhs = -model.K_b @ q[:m] - model.D_b @ v[:m] - z[:m]
    tau = M[m:, :m].dot(solve(M[:m, :m], rhs)) + z[m:]  # H_bm^T x_b'' + ..., M symmetric
    if model.has_joint_damping:
        tau += model.D_m @ v[m:]
    return tau


def _one_dof_base_torques(
    model: FsmsModel, cp: Coupling, q: np.ndarray, v: np.ndarray, thetaddot: np.ndarray
) -> np.ndarray:
    """:func:`realize_acceleration` for a 1-DOF base: x_b'' as a number from the floats of ``cp.row``,
    then the arm rows of Eq. (1) as one product M_arm (x_b'', theta'') (fewer numpy calls than blocks)."""
    M, c = cp.M, cp.c
    H_b, *h = cp.row.M_rows[0] if cp.row is not None else M[0].tolist()
    spring = -model.K_b.item(0) * q.item(0) - model.D_b.item(0) * v.item(0)
    accelerations = thetaddot.tolist()
    xddot_b = (spring - c.item(0) - sum(map(operator.mul, h, accelerations))) / H_b
    tau = (M.dot(np.array((xddot_b, *accelerations))) + c)[1:]  # the arm rows: fewer numpy calls than M[1:]
    if model.has_joint_damping:
        tau += model.D_m @ v[1:]
    return tau
