"""Step log: one row per control step in a fixed-size ring buffer (bounded memory in long runs), its
columns and their units."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING, NamedTuple

import numpy as np

from rns_viz.csvio import write_csv
from rns_viz.sim.ring import Ring

if TYPE_CHECKING:
    from rns_viz.control.common import ControlOutput
    from rns_viz.model import FsmsModel

RowCompleter = Callable[[np.ndarray], None]  # fills derived columns of a block of new rows in place


def log_columns(m: int, n: int, r: int, p: int) -> list[str]:
    """Column names, SI units and radians (documentation: CSV formats)."""

    def seq(prefix: str, k: int) -> list[str]:
        return [f"{prefix}_{i + 1}" for i in range(k)]

    return [
        "t",
        *seq("xb", m),
        *seq("xbdot", m),
        *seq("theta", n),
        *seq("thetadot", n),
        *seq("tau", n),
        *seq("fext", m),
        "ee_x",
        "ee_y",
        "ee_z",
        *seq("L", r),
        "sigma_hbm",
        "sigma_jbar",
        *seq("theta_ref", n),
        *[f"ee_ref_{a}" for a in "xyz"[:p]],
    ]


class CoordinateUnits(NamedTuple):
    """The units of one coordinate's position, velocity, force and momentum."""

    position: str
    velocity: str
    force: str
    momentum: str


TRANSLATION = CoordinateUnits("m", "m/s", "N", "kg m/s")  # a prismatic joint's coordinate
ROTATION = CoordinateUnits("rad", "rad/s", "N m", "kg m^2/s")  # a revolute joint's


def base_units(model: FsmsModel) -> list[CoordinateUnits]:
    """The units of each base coordinate x_b,i (a rotation where its joint is revolute)."""
    return [ROTATION if turns else TRANSLATION for turns in model.base_rotational]


def arm_units(model: FsmsModel) -> list[CoordinateUnits]:
    """The units of each joint angle theta_i (a length where its joint is prismatic)."""
    joints = model.pin_model.joints[model.m + 1 :]  # pinocchio's joint 0 is the universe
    return [TRANSLATION if joint.shortname().startswith("JointModelP") else ROTATION for joint in joints]


def log_units(model: FsmsModel) -> list[str]:
    """The unit of each column of :func:`log_columns` for ``model`` (documentation: CSV formats): L_i, a row of
    S H_bm theta', is a linear or an angular momentum as its base row is a translation or a rotation."""
    base, arm = base_units(model), arm_units(model)
    return [
        "s",
        *(u.position for u in base),
        *(u.velocity for u in base),
        *(u.position for u in arm),
        *(u.velocity for u in arm),
        *(u.force for u in arm),
        *(u.force for u in base),
        *["m"] * 3,
        *(base[i].momentum for i in model.selected),
        "kg m",  # sigma_min(W S H_bm), moment rows divided by the arm's reach (rns.singularity_distance)
        "m/rad",  # sigma_min of the restricted Jacobian J-bar
        *(u.position for u in arm),
        *["m"] * len(model.task_rows),
    ]


class RowLayout:
    """Where each quantity of a step goes in a row of :func:`log_columns` (index arrays and slices)."""

    def __init__(self, model: FsmsModel) -> None:
        m, n = model.m, model.n
        r, p = len(model.selected), len(model.task_rows)
        self.columns = log_columns(m, n, r, p)
        self.units = log_units(model)
        col = {name: i for i, name in enumerate(self.columns)}
        # The stacked state (x_b, theta, x_b', theta') goes to columns xb, theta, xbdot, thetadot.
        names = [f"xb_{i + 1}" for i in range(m)] + [f"theta_{i + 1}" for i in range(n)]
        names += [f"xbdot_{i + 1}" for i in range(m)] + [f"thetadot_{i + 1}" for i in range(n)]
        self.state = np.array([col[name] for name in names])
        self.theta = slice(col["theta_1"], col["theta_1"] + n)
        self.tau = slice(col["tau_1"], col["tau_1"] + n)
        self.fext = slice(col["fext_1"], col["fext_1"] + m)
        self.ee = slice(col["ee_x"], col["ee_x"] + 3)
        self.coupling = slice(col["L_1"], col["L_1"] + r)
        self.sigma_hbm = col["sigma_hbm"]
        self.sigma_jbar = col["sigma_jbar"]
        self.theta_ref = slice(col["theta_ref_1"], col["theta_ref_1"] + n)
        self.ee_ref = slice(self.theta_ref.stop, self.theta_ref.stop + p)
        self.references = slice(self.theta_ref.start, self.ee_ref.stop)

    def write(self, row: np.ndarray, t: float, x: np.ndarray, out: ControlOutput, f: np.ndarray | None) -> None:
        """Fill ``row`` for the step from state x = (q, v) at time t; the end-effector columns are left."""
        row[0] = t
        row[self.state] = x
        row[self.tau] = out.tau
        row[self.fext] = 0.0 if f is None else f
        row[self.coupling] = out.coupling_momentum
        row[self.sigma_hbm] = out.sigma_hbm
        row[self.sigma_jbar] = out.sigma_jbar
        row[self.references] = np.nan  # theta_ref and ee_ref: the last columns
        if out.theta_ref is not None:
            row[self.theta_ref] = out.theta_ref
        if out.ee_ref is not None:
            row[self.ee_ref.start : self.ee_ref.start + len(out.ee_ref)] = out.ee_ref


class StepLog(Ring):
    """The newest ``capacity`` rows of a run, one per step, the oldest dropped first (a :class:`Ring`).

    ``complete``, if given, fills derived columns (the end-effector position) of newly added rows
    in place, in blocks, when the log is next read: a step only pays for what it measured.
    """

    def __init__(
        self, columns: list[str], units: list[str], capacity: int, complete: RowCompleter | None = None
    ) -> None:
        if capacity < 1:
            raise ValueError("log capacity must be at least one row")
        super().__init__(capacity, len(columns))
        self.columns = columns
        self.units = units
        self.index = {name: i for i, name in enumerate(columns)}
        self._complete = complete
        self._completed = 0  # rows appended (Ring.appended) when the derived columns were last filled

    def clear(self) -> None:
        super().clear()
        self._completed = 0

    def newest(self, k: int | None = None, column: int | None = None) -> np.ndarray:
        """As :meth:`Ring.newest`, the derived columns filled first."""
        self._complete_rows()
        return super().newest(k, column)

    def array(self, last: int | None = None) -> np.ndarray:
        """The rows in time order (a copy); ``last`` limits to the newest rows."""
        return self.newest(last)

    def column(self, name: str, last: int | None = None) -> np.ndarray:
        return self.newest(last, self.index[name])

    def _complete_rows(self) -> None:
        k = min(self.appended - self._completed, len(self))
        self._completed = self.appended
        if self._complete is not None and k:
            for block in self.blocks(k):
                self._complete(block)

    def write_csv(self, target: str | Path | IO[str], last: int | None = None) -> int:
        """Write the kept rows (``last``: the newest only) with units in the header (rns_viz.csvio) to a
        path or a text stream; returns the rows written."""
        return write_csv(target, self.columns, self.units, self.array(last))
