"""A lesson in progress: observes the loop's state every few steps and reports the task's progress."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from rns_viz.live.lessons import LESSONS, Check, Lesson, RunView
from rns_viz.live.records import LessonStatus

if TYPE_CHECKING:
    from rns_viz.live.state import LiveState

OBSERVE_EVERY = 10  # steps between observations (10 ms)


class LessonRun:
    def __init__(self, model: str, number: int) -> None:
        self.model, self.number = model, number
        self.lesson: Lesson = LESSONS[model][number - 1]
        self.check: Check | None = None  # made on the first observation, with the loop's model

    def observe(self, state: LiveState) -> None:
        runs, op = state.runs, state.operator
        model = state.model
        if self.check is None:
            self.check = self.lesson.check(model)
        m = model.m
        theta = runs.sim.q[m:].copy()
        target = op.target[:2].copy() if op is not None and op.target is not None else None
        self.check.observe(
            RunView(
                epoch=state.epoch,
                t=runs.t,
                x_b=float(runs.sim.q[model.selected[0]]),
                x_b_shadow=float(runs.shadow.q[model.selected[0]]) if state.settings.shadow else math.nan,
                theta=theta,
                ee=model.ee_position(theta)[:2],
                mode=op.mode if op is not None else "preset",
                kicks=state.kicks_sent,
                sigma_hbm=state.outputs.readouts.sigma_hbm,
                ee_target=None if target is None else np.asarray(target),
                targets_moved=state.targets_moved,
            )
        )

    def status(self) -> LessonStatus:
        progress = self.check.progress() if self.check is not None else None
        lesson = self.lesson
        return LessonStatus(
            model=self.model,
            number=self.number,
            count=len(LESSONS[self.model]),
            title=lesson.title,
            equation=lesson.equation,
            text=lesson.text,
            task=lesson.task,
            done=progress.done if progress is not None else False,
            progress=progress.message if progress is not None else "",
        )
