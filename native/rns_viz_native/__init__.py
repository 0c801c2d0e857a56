"""rns_viz's optional C++ closed-loop step (``pip install ./native`` from the rns_viz repository).

``RobotModel`` builds the pinocchio model from URDF text in C++ and ``ClosedLoop`` runs a law and
one RK4 step on it; rns_viz.sim.native drives them. Importing refuses (ImportError with the reason)
when the pinocchio loaded in Python is not the release this module was compiled against: the
compiled code and pinocchio's Python bindings must share one libpinocchio.
"""

from __future__ import annotations

import pinocchio  # first: loads the libpinocchio that _core links (one copy in the process)

from rns_viz_native._core import API_VERSION, PINOCCHIO_VERSION, ClosedLoop, RobotModel

if pinocchio.__version__ != PINOCCHIO_VERSION:
    raise ImportError(
        f"rns_viz_native was built against pinocchio {PINOCCHIO_VERSION} but pinocchio {pinocchio.__version__} "
        "is installed; rebuild it with: pip install ./native"
    )

__all__ = ["API_VERSION", "PINOCCHIO_VERSION", "ClosedLoop", "RobotModel"]
