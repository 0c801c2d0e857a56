"""Without a usable native module rns_viz steps in Python, says why once, and gives the same results.

These run in the default install (no native module): a module that is missing, built for another
rns_viz (API version) or that fails to import (a library or pinocchio version mismatch raises
ImportError) is refused with a one-line reason, which ``rns-viz info`` reports.
"""

from __future__ import annotations

import importlib
import json
import sys
import types
import warnings
from pathlib import Path

import numpy as np
import pytest

from rns_viz import _native, cli
from rns_viz.control import AccelerationLaw, Gains
from rns_viz.model import FsmsModel
from rns_viz.sim import ForcePulse, Simulator, native

BROKEN = "libpinocchio_default.so: cannot open shared object file: No such file or directory"


def fake_module(monkeypatch: pytest.MonkeyPatch, module: types.ModuleType) -> None:
    monkeypatch.setitem(sys.modules, "rns_viz_native", module)


def broken_install(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """An installed rns_viz_native whose compiled part cannot be loaded."""
    package = tmp_path / "rns_viz_native"
    package.mkdir()
    (package / "__init__.py").write_text(f"raise ImportError({BROKEN!r})\n")
    monkeypatch.delitem(sys.modules, "rns_viz_native", raising=False)
    monkeypatch.syspath_prepend(str(tmp_path))


def test_a_module_for_another_rns_viz_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    stale = types.ModuleType("rns_viz_native")
    stale.API_VERSION = _native.API_VERSION - 1  # type: ignore[attr-defined]
    fake_module(monkeypatch, stale)
    core, why = _native._load()
    assert core is None and why is not None
    assert f"needs {_native.API_VERSION}" in why and "pip install ./native" in why and "\n" not in why


def test_a_module_that_fails_to_import_is_refused(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    broken_install(monkeypatch, tmp_path)
    core, why = _native._load()
    assert core is None and why == f"rns_viz_native did not import ({BROKEN})"


def test_an_unusable_module_warns_once_and_the_python_step_runs(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, trep: FsmsModel
) -> None:
    model = trep
    law = AccelerationLaw(model, Gains(g_b=20.0, g_m=5.0))
    kick = ForcePulse(0.01, 0.05, (2.0,))
    reference = Simulator(model, law, force=kick, native=False)
    reference.run(0.2)
    broken_install(monkeypatch, tmp_path)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            importlib.reload(_native)
        assert [str(w.message) for w in caught if w.category is RuntimeWarning] == [
            f"rns_viz: using the Python step: {_native.why}"
        ]
        assert not native.available() and native.unavailable_reason() == _native.why
        sim = Simulator(model, law, force=kick)
        assert not sim.native
        sim.run(0.2)
        assert np.array_equal(sim.log.array(), reference.log.array(), equal_nan=True)  # same, in Python
    finally:
        monkeypatch.undo()
        importlib.reload(_native)  # back to what is installed


def test_info_says_which_step_runs(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["info", "--model", "trep"]) in (0, None)
    info = json.loads(capsys.readouterr().out)
    assert info["native_step"] is native.available()
    if native.available():
        assert "native_step_unavailable" not in info
    else:
        assert info["native_step_unavailable"] == native.unavailable_reason()
        if "rns_viz_native" not in sys.modules:
            assert "not installed" in info["native_step_unavailable"]
