"""The live session's slow work: path tables, reachable sets, path families and preset builds.

:class:`Background` submits each request to the worker thread (which runs the geometry in a helper
process, :mod:`rns_viz.live.jobs.helper`) tagged with the loop's epoch, and hands back typed results of the
current epoch only: a result computed for a model or preset that has since been left is dropped here.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from rns_viz.live.jobs import helper as jobs
from rns_viz.live.jobs.worker import Worker
from rns_viz.live.reach.region import ReachRegion
from rns_viz.paths import PathTable
from rns_viz.scenarios import LIVE_SCENARIOS
from rns_viz.sim import Simulator

FAMILY_SIZE = 24  # curves of the Fig. 8 path family drawn


@dataclass(frozen=True)
class FamilyReady:
    model: str
    curves: list[np.ndarray]  # end-effector curves, base frame, m


@dataclass(frozen=True)
class TableReady:
    table: PathTable
    default: bool  # the path through the model's default configuration (kept for the next reset)


@dataclass(frozen=True)
class ReachReady:
    region: ReachRegion


@dataclass(frozen=True)
class PresetReady:
    name: str
    sims: tuple[Simulator, Simulator]  # the operated run and a copy for the shadow


@dataclass(frozen=True)
class JobFailed:
    kind: str
    error: str


Ready = FamilyReady | TableReady | ReachReady | PresetReady | JobFailed


def _build_preset(name: str) -> tuple[Simulator, Simulator]:
    scenario = LIVE_SCENARIOS[name]
    return scenario.build(), scenario.build()


class Background:
    def __init__(self) -> None:
        self.worker = Worker()
        self.families: dict[str, list[np.ndarray]] = {}  # per model, kept across resets

    def family(self, epoch: int, model: str) -> None:
        if model not in self.families:
            self.worker.submit("family", (epoch, model), lambda: jobs.call("family_curves", model, FAMILY_SIZE))

    def path_table(self, epoch: int, model: str, seed: np.ndarray, default: bool = False) -> None:
        seed = np.array(seed, dtype=float)
        self.worker.submit("table", (epoch, default), lambda: jobs.call("path_table", model, seed))

    def reach(self, epoch: int, model: str, seed: np.ndarray) -> None:
        seed = np.array(seed, dtype=float)
        self.worker.submit("reach", (epoch,), lambda: jobs.call("reach_region", model, seed))

    def preset(self, epoch: int, name: str) -> None:
        self.worker.submit("preset", (epoch, name), lambda: _build_preset(name))

    def has_results(self) -> bool:
        return self.worker.has_results()

    def results(self, epoch: Callable[[], int]) -> Iterator[Ready]:
        """Finished results of the current ``epoch()`` (families for any), oldest first; failures as
        :class:`JobFailed`. The epoch is read for each result: taking one may start a new epoch."""
        for res in self.worker.collect():
            if res.error is not None:
                yield JobFailed(res.kind, res.error)
            elif res.kind == "family":
                self.families[res.tag[1]] = res.value
                yield FamilyReady(res.tag[1], res.value)
            elif res.tag[0] != epoch():
                continue
            elif res.kind == "table":
                yield TableReady(res.value, res.tag[1])
            elif res.kind == "reach":
                yield ReachReady(res.value)
            elif res.kind == "preset":
                yield PresetReady(res.tag[1], res.value)

    def idle(self) -> bool:
        return self.worker.idle()

    def wait_idle(self, timeout: float) -> bool:
        return self.worker.wait_idle(timeout)

    def stop(self) -> None:
        self.worker.stop()
