"""The optional compiled step: the separate distribution ``rns-viz-native`` (``pip install ./native``).

``core`` is the module ``rns_viz_native`` when it is installed and usable, else None, and ``why``
then says why (not installed; built for another pinocchio or another rns_viz; a library missing).
An installed module that cannot be used is reported once with a RuntimeWarning; everything then
runs in Python with the same results. :func:`robot_model` gives the C++ pinocchio model of a
:class:`~rns_viz.model.FsmsModel`, built from the same URDF text and gravity, and checked against
the Python model (crba and nonLinearEffects equal) before anything uses it.
"""

from __future__ import annotations

import warnings
import weakref
from types import ModuleType
from typing import Any

import numpy as np
import pinocchio as pin

from rns_viz.model import FsmsModel

API_VERSION = 3  # the calls rns_viz.sim.native makes; rns_viz_native.API_VERSION must equal it
INSTALL_HINT = "pip install ./native from the rns_viz repository"
MODEL_TOLERANCE = 1e-12  # relative: the C++ model must give pinocchio's Python numbers
NOT_INSTALLED = f"rns_viz_native is not installed (optional: {INSTALL_HINT})"


def _load() -> tuple[ModuleType | None, str | None]:
    try:
        import rns_viz_native as module
    except ModuleNotFoundError as exc:
        if exc.name == "rns_viz_native":  # the default install: not an error, nothing to warn about
            return None, NOT_INSTALLED
        return None, f"rns_viz_native did not import ({exc})"
    except Exception as exc:  # ImportError from a missing library or a pinocchio version mismatch
        return None, f"rns_viz_native did not import ({exc})"
    found = getattr(module, "API_VERSION", None)
    if found != API_VERSION:
        return None, f"rns_viz_native has API version {found}, this rns_viz needs {API_VERSION}: {INSTALL_HINT}"
    return module, None


def _warn(reason: str) -> None:
    warnings.warn(f"rns_viz: using the Python step: {reason}", RuntimeWarning, stacklevel=3)


core: ModuleType | None
why: str | None
core, why = _load()
if core is None and why is not None and why != NOT_INSTALLED:
    _warn(why)

_robots: weakref.WeakKeyDictionary[FsmsModel, Any] = weakref.WeakKeyDictionary()
_refused: set[str] = set()


def robot_model(model: FsmsModel) -> Any | None:
    """``rns_viz_native.RobotModel`` for this model (cached), or None: no native module, or the
    C++ model does not reproduce the Python one (then one warning says so)."""
    if core is None:
        return None
    robot = _robots.get(model)
    if robot is None:
        try:
            robot = core.RobotModel(model.spec.urdf_path.read_text(), np.asarray(model.spec.gravity, dtype=float))
            mismatch = model_mismatch(model, robot)
        except Exception as exc:  # pinocchio's C++ parser refused what its Python side read
            mismatch = f"it was not built: {exc}"
        if mismatch is not None:
            if str(model.spec.urdf_path) not in _refused:
                _refused.add(str(model.spec.urdf_path))
                _warn(f"the C++ model of {model.name} differs from pinocchio's Python model ({mismatch})")
            return None
        _robots[model] = robot
    return robot


def model_mismatch(model: FsmsModel, robot: Any) -> str | None:
    """Where the C++ model's M(q) and c(q, v) of Eq. (1) differ from the Python model's at a few
    states (None: equal to MODEL_TOLERANCE)."""
    if robot.nv != model.nv:
        return f"nv {robot.nv} != {model.nv}"
    pin_model, rng = model.pin_model, np.random.default_rng(0)
    data = pin_model.createData()
    for _ in range(3):
        q = np.clip(rng.uniform(-1.0, 1.0, model.nv), pin_model.lowerPositionLimit, pin_model.upperPositionLimit)
        v = rng.normal(0.0, 1.0, model.nv)
        M, c = model.mass_matrix(q), pin.nonLinearEffects(pin_model, data, q, v)
        pairs = (("crba", robot.mass_matrix(q), M), ("nonLinearEffects", robot.nonlinear_effects(q, v), c))
        for name, got, want in pairs:
            error = float(np.max(np.abs(got - want)))
            if not error <= MODEL_TOLERANCE * max(1.0, float(np.max(np.abs(want)))):
                return f"{name} differs by {error:.3g}"
    return None
