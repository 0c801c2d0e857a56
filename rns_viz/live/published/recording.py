"""The immutable recordings taken from the live session's recorder, and their CSV.

:meth:`~rns_viz.live.outputs.recorder.Recorder.take` copies the newest N seconds of the ring buffer into a
:class:`Recording`: read-only arrays that any thread may replay, plot or export (CSV with units in the
header, reading back bit-exact). Per step it holds the operated run's step-log row (t, x_b, x_b', θ, θ', τ,
the base force, L, the distances to singularity and the law's references θ_ref / x_ref, exactly the floats
of the simulation log), the shadow run's state, L and τ at the same t, the arm's reaction on the base
(Eq. 1) as the readout showed it (every base row: the wrench a 6-DOF base draws as arrows) and whether
suppression was on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from rns_viz.csvio import csv_text
from rns_viz.live.published.plot_buffers import PLOT_SERIES
from rns_viz.model import FsmsModel
from rns_viz.sim.log import base_units

PLOT_WINDOW_S = 10.0  # s: the live plots' window, replayed alike
PLOT_EVERY = 20  # steps between replayed plot samples (50 Hz, as live)
SUPPRESS = "suppress"  # 1.0 while the operated run had suppression on


def reaction_columns(m: int) -> tuple[str, ...]:
    """The reaction's columns, Eq. (1)'s −(H_bm θ'' + c_b): ``reaction`` (N) for a 1-DOF base, else one
    per base row, ``reaction_1 .. reaction_m`` (N along a translation, N m about a rotation)."""
    return ("reaction",) if m == 1 else tuple(f"reaction_{i + 1}" for i in range(m))


def reaction_units(model: FsmsModel) -> tuple[str, ...]:
    """The units of :func:`reaction_columns`: a force (N) on a translation, a moment (N m) on a rotation."""
    return tuple(u.force for u in base_units(model))


@dataclass(frozen=True, eq=False)
class Recording:
    """Steps of one run, oldest first: ``data[k]`` is the state at ``t[k]`` and what happened over the
    step from there. Read-only; ``model`` is the loop's model instance (kinematics only, own data)."""

    columns: tuple[str, ...]
    units: tuple[str, ...]  # of each column (the step log's, rns_viz.sim.log.log_units)
    data: np.ndarray  # (steps, columns), float64, read-only
    model: FsmsModel = field(repr=False)
    dt: float  # s
    index: dict[str, int] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.data.setflags(write=False)
        object.__setattr__(self, "index", {name: i for i, name in enumerate(self.columns)})

    def __len__(self) -> int:
        return len(self.data)

    @property
    def t(self) -> np.ndarray:
        return self.data[:, 0]

    @property
    def span(self) -> tuple[float, float]:
        """First and last recorded time, s (simulation time)."""
        return float(self.data[0, 0]), float(self.data[-1, 0])

    def columns_of(self, prefix: str) -> np.ndarray:
        """Column indices ``prefix_1 .. prefix_k``."""
        k = 1
        out = []
        while f"{prefix}_{k}" in self.index:
            out.append(self.index[f"{prefix}_{k}"])
            k += 1
        return np.array(out, dtype=int)

    def at(self, t: float) -> int:
        """The newest step at or before time ``t`` (clamped to the recording)."""
        return int(np.clip(np.searchsorted(self.t, t + 0.5 * self.dt, side="right") - 1, 0, len(self) - 1))

    def q(self, k: int) -> np.ndarray:
        """(x_b, θ) of the operated run at step k."""
        return self.data[k, self._q]

    def v(self, k: int) -> np.ndarray:
        return self.data[k, self._v]

    def q_shadow(self, k: int) -> np.ndarray | None:
        """(x_b, θ) of the shadow run at step k; None where it was not running."""
        q = self.data[k, self._q_shadow]
        return q if np.all(np.isfinite(q)) else None

    def value(self, k: int, name: str) -> float:
        return float(self.data[k, self.index[name]])

    @cached_property
    def _q(self) -> np.ndarray:
        return np.concatenate((self.columns_of("xb"), self.columns_of("theta")))

    @cached_property
    def _v(self) -> np.ndarray:
        return np.concatenate((self.columns_of("xbdot"), self.columns_of("thetadot")))

    @cached_property
    def _q_shadow(self) -> np.ndarray:
        return np.concatenate((self.columns_of("shadow_xb"), self.columns_of("shadow_theta")))

    # ---------------------------------------------------------------- derived
    def _ee(self, rows: np.ndarray, prefix: str) -> np.ndarray:
        """End-effector positions (K, 3) of the given rows' joint angles (``theta`` or ``theta_ref``), m."""
        thetas = self.data[np.ix_(rows, self.columns_of(prefix))]
        out = np.full((len(rows), 3), np.nan)
        ok = np.all(np.isfinite(thetas), axis=1)
        if np.any(ok):
            out[ok] = self.model.ee_positions(thetas[ok], self._pin_data)
        return out

    @cached_property
    def _pin_data(self) -> object:
        return self.model.pin_model.createData()  # never the loop's or the laws' data

    @cached_property
    def table(self) -> np.ndarray:
        """All rows with the end-effector columns filled from θ, as the step log fills them on reading."""
        out = self.data.copy()
        if "ee_x" in self.index:
            ee = self.index["ee_x"]
            out[:, ee : ee + 3] = self._ee(np.arange(len(self)), "theta")
        out.setflags(write=False)
        return out

    @cached_property
    def _plot_rows(self) -> dict[str, np.ndarray]:
        """The live plots' series (PLOT_SERIES; x_b in mm, L in kg m/s, error in mm) every PLOT_EVERY steps."""
        rows = np.arange(0, len(self), PLOT_EVERY)
        d, i = self.data, self.index
        x = self._ee(rows, "theta")[:, :2]
        ref = self._ee(rows, "theta_ref")[:, :2]
        for a, col in enumerate(("ee_ref_x", "ee_ref_y")):
            if col in i:
                own = d[rows, i[col]]
                ref[:, a] = np.where(np.isfinite(own), own, ref[:, a])
        base = d[rows][:, self.columns_of("xb")] * 1e3  # mm (mrad for a rotation)
        coordinates = {f"xb_{k + 1}": base[:, k] if k < base.shape[1] else 0.0 * base[:, 0] for k in range(6)}
        return {
            "t": d[rows, 0],
            "xb": _plotted(base),
            "xb_shadow": _plotted(d[rows][:, self.columns_of("shadow_xb")] * 1e3),
            "L": _plotted(d[rows][:, self.columns_of("L")]),
            "L_shadow": _plotted(d[rows][:, self.columns_of("shadow_L")]),
            "ee_error": np.linalg.norm(ref - x, axis=1) * 1e3,
            "suppress": d[rows, i["suppress"]],
            **coordinates,
        }

    def plot_arrays(self, t: float) -> dict[str, np.ndarray]:
        """The plots as they looked at time ``t``: the last PLOT_WINDOW_S seconds up to t (copies)."""
        rows = self._plot_rows
        lo, hi = np.searchsorted(rows["t"], (t - PLOT_WINDOW_S, t + 0.5 * self.dt), side="right")
        return {name: rows[name][lo:hi].copy() for name in PLOT_SERIES}

    def ee_error(self, k: int) -> float:
        """|x_ref − x_e| at step k, m (NaN without a reference)."""
        x = self._ee(np.array([k]), "theta")[0, :2]
        ref = self._ee(np.array([k]), "theta_ref")[0, :2]
        for a, col in enumerate(("ee_ref_x", "ee_ref_y")):
            if col in self.index and math.isfinite(self.data[k, self.index[col]]):
                ref[a] = self.data[k, self.index[col]]
        return float(np.linalg.norm(ref - x))

    def wrench(self, k: int) -> tuple[float, ...]:
        """The recorded reaction's base rows at step k (N, N m); () before the first evaluation."""
        w = self.data[k, self._reaction]
        return tuple(float(x) for x in w) if np.all(np.isfinite(w)) else ()

    @cached_property
    def _reaction(self) -> np.ndarray:
        return np.array([self.index[name] for name in reaction_columns(self.model.m)], dtype=int)

    def csv(self) -> bytes:
        """Every step as CSV (rns_viz.csvio): units in the header, 17 significant digits (reads back bit-exact)."""
        return csv_text(self.columns, self.units, self.table).encode()


def _plotted(columns: np.ndarray) -> np.ndarray:
    """What the live plots show of a block of coordinates (rows x k): the one column, or the length of the
    first three (a base's translation, the linear momentum), as rns_viz.live.outputs.step_outputs plots it live."""
    return columns[:, 0] if columns.shape[1] == 1 else np.sqrt(np.sum(columns[:, :3] ** 2, axis=1))
