"""What every lesson is made of: the run a check sees (:class:`RunView`), the check itself and what it
reports, and the lesson (text, the paper's equation, the state it loads, its check). Nothing here
imports viser; the lessons themselves are in :mod:`rns_viz.live.teaching.lessons` and
:mod:`rns_viz.live.teaching.lessons_boom`.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rns_viz.control import LawKind
from rns_viz.model import FsmsModel
from rns_viz.rns import singularity_distance


@dataclass(frozen=True)
class RunView:
    """What a check may look at after a step (SI units; x_b the base deflection along S's first row)."""

    epoch: int
    t: float  # s
    x_b: float  # m, operated run
    x_b_shadow: float  # m, the shadow run (nan without it)
    theta: np.ndarray  # rad
    ee: np.ndarray  # (x, y) m, base frame
    mode: str  # what the operator's reference is doing
    kicks: int  # kicks since the lesson started
    sigma_hbm: float  # kg m, smallest singular value of S H_bm
    ee_target: np.ndarray | None  # (x, y) m, where the arm is sent; None without one
    targets_moved: int  # dragged targets moved onto the path / into the reachable set so far
    base: np.ndarray | None = None  # (m,) m or rad: every base coordinate of the operated run
    base_shadow: np.ndarray | None = None  # (m,) the shadow run's (None without it)
    thetadot: np.ndarray | None = None  # (n,) rad/s, operated run


@dataclass(frozen=True)
class Progress:
    done: bool
    message: str  # for the student: what is measured now


class Check:
    """Observes runs; subclasses keep what they need and say :meth:`progress`."""

    def __init__(self, model: FsmsModel) -> None:
        self.model = model
        H_b = float(model.mass_matrix(model.q(model.spec.default_configuration))[0, 0])
        self.period = 2 * math.pi * math.sqrt(H_b / float(model.K_b[0, 0]))  # s, the base's swing
        theta0 = model.spec.default_configuration  # the readout's distance to singularity there (kg m)
        self.sigma0 = float(singularity_distance(model.coupling_matrix(model.q(theta0)), model.coupling_weights))
        self._epoch: int | None = None
        self.done = False

    def observe(self, view: RunView) -> None:
        if view.epoch != self._epoch:  # the run restarted: so does the task
            self._epoch, self.done = view.epoch, False
            self.restart(view)
        if not self.done:
            self.update(view)

    def restart(self, view: RunView) -> None: ...

    def update(self, view: RunView) -> None: ...

    def progress(self) -> Progress:
        raise NotImplementedError


class Envelope:
    """max |x| over the last ``window`` s, from samples every observation."""

    def __init__(self, window: float) -> None:
        self.window = window
        self.samples: deque[tuple[float, float]] = deque()

    def add(self, t: float, x: float) -> float:
        self.samples.append((t, abs(x)))
        while self.samples and self.samples[0][0] < t - self.window:
            self.samples.popleft()
        return max(v for _, v in self.samples)


@dataclass(frozen=True)
class LessonStart:
    """The state a lesson loads: a fresh run of ``model`` at rest, the law, suppression, shadow shown."""

    model: str
    law: LawKind
    suppress: bool


@dataclass(frozen=True)
class Lesson:
    name: str  # what a parameter file's [app] lessons calls it
    title: str
    equation: str  # the paper's equation(s) it is about
    text: str  # one or two sentences of explanation
    task: str  # what the student does
    start: LessonStart
    check: Callable[[FsmsModel], Check]
    look: str = ""  # what to watch on screen while doing the task (plain words)
