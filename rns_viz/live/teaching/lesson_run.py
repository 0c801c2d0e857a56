"""A lesson in progress: observes the loop's state every few steps and reports the task's progress."""

from __future__ import annotations

import math

from rns_viz.live.operator.operator import Operator
from rns_viz.live.published.snapshot import LessonStatus
from rns_viz.live.runs.run_pair import RunPair
from rns_viz.live.teaching.lessons import Check, Lesson, RunView, lessons_for
from rns_viz.model import FsmsModel
from rns_viz.params import model_source

OBSERVE_EVERY = 10  # steps between observations (10 ms)


class LessonRun:
    def __init__(self, model: str, number: int) -> None:
        self.model, self.number = model, number  # the model offering the lesson, and where in its list
        self.count = len(lessons := lessons_for(model))
        self.lesson: Lesson = lessons[number - 1]
        self.check: Check | None = None  # made on the first observation, with the loop's model

    @property
    def home(self) -> str:
        """The model the lesson runs on (its start's, without the selection)."""
        return model_source(self.lesson.start.model)

    def observe(self, model: FsmsModel, view: RunView) -> None:
        if self.check is None:
            self.check = self.lesson.check(model)  # with the loop's own model instance
        self.check.observe(view)

    def status(self) -> LessonStatus:
        progress = self.check.progress() if self.check is not None else None
        lesson = self.lesson
        return LessonStatus(
            model=self.model,
            number=self.number,
            count=self.count,
            title=lesson.title,
            equation=lesson.equation,
            text=lesson.text,
            task=lesson.task,
            look=lesson.look,
            done=progress.done if progress is not None else False,
            progress=progress.message if progress is not None else "",
        )


def run_view(
    model: FsmsModel,
    epoch: int,
    runs: RunPair,
    op: Operator | None,
    shadow: bool,
    counts: tuple[int, int],
    sigma: float,
) -> RunView:
    """What a lesson's check sees now; ``counts`` = (kicks, dragged targets moved) so far, ``sigma`` of S H_bm."""
    theta = runs.sim.q[model.m :].copy()
    row = int(model.selected[0])
    target = op.target[:2].copy() if op is not None and op.target is not None else None
    return RunView(
        epoch=epoch,
        t=runs.t,
        x_b=float(runs.sim.q[row]),
        x_b_shadow=float(runs.shadow.q[row]) if shadow else math.nan,
        theta=theta,
        ee=model.ee_position(theta)[:2],
        mode=op.mode if op is not None else "preset",
        kicks=counts[0],
        sigma_hbm=sigma,
        ee_target=target,
        targets_moved=counts[1],
        base=runs.sim.q[: model.m].copy(),
        base_shadow=runs.shadow.q[: model.m].copy() if shadow else None,
        thetadot=runs.sim.v[model.m :].copy(),
    )
